

module top(clock,requests,advance,hold,grant,granted);
    
    // Module arguments
    input wire  clock;
    input wire  [31:0] requests;
    input wire  advance;
    input wire  hold;
    output reg  [31:0] grant;
    output reg  granted;
    
    // Constant declarations
    localparam  n = 6'b100000;
    localparam  mask = 32'hffffffff;
    
    // Stub signals
    reg  [31:0] last_grant$d;
    wire  [31:0] last_grant$q;
    reg  last_grant$clock;
    reg  [31:0] at_or_below_last$d;
    wire  [31:0] at_or_below_last$q;
    reg  at_or_below_last$clock;
    
    // Local signals
    reg  [31:0] above_last;
    reg  [63:0] both;
    reg  [63:0] both_less;
    reg  [63:0] lowest;
    reg  [63:0] upto;
    reg  [31:0] next_at_or_below;
    
    // Sub module instances
    top$last_grant last_grant(
        .d(last_grant$d),
        .q(last_grant$q),
        .clock(last_grant$clock)
    );
    top$at_or_below_last at_or_below_last(
        .d(at_or_below_last$d),
        .q(at_or_below_last$q),
        .clock(at_or_below_last$clock)
    );
    
    // Update code
    always @(*) begin
        last_grant$clock = clock;
        at_or_below_last$clock = clock;
        last_grant$d = last_grant$q;
        at_or_below_last$d = at_or_below_last$q;
        above_last = requests & (~at_or_below_last$q);
        both = (((requests) & 64'hffffffffffffffff) << n) | ((above_last) & 64'hffffffffffffffff);
        both_less = both - 32'h1;
        lowest = both & (~both_less);
        upto = both ^ both_less;
        if (hold) begin
            grant = last_grant$q;
            next_at_or_below = (last_grant$q << 32'h1) - 32'h1;
        end
        else begin
            grant = (((lowest) & 32'hffffffff) & mask) | ((lowest >> n) & 32'hffffffff);
            if (upto[n]) begin
                next_at_or_below = ((upto >> n) & 32'hffffffff);
            end
            else begin
                next_at_or_below = ((upto) & 32'hffffffff);
            end
        end
        granted = |requests;
        if (advance) begin
            last_grant$d = grant & mask;
            at_or_below_last$d = next_at_or_below & mask;
        end
    end
    
endmodule // top


module top$at_or_below_last(d,q,clock);
    
    // Module arguments
    input wire  [31:0] d;
    output reg  [31:0] q;
    input wire  clock;
    
    // Update code (custom)
    initial begin
       q = 32'h0;
    end
    
    always @(posedge clock) begin
       q <= d;
    end
          
endmodule // top$at_or_below_last


module top$last_grant(d,q,clock);
    
    // Module arguments
    input wire  [31:0] d;
    output reg  [31:0] q;
    input wire  clock;
    
    // Update code (custom)
    initial begin
       q = 32'h0;
    end
    
    always @(posedge clock) begin
       q <= d;
    end
          
endmodule // top$last_grant
