

module top(clock,requests,advance,hold,grant,granted,last_grant);
    
    // Module arguments
    input wire  clock;
    input wire  [31:0] requests;
    input wire  advance;
    input wire  hold;
    output reg  [31:0] grant;
    output reg  granted;
    output reg  [31:0] last_grant;
    
    // Constant declarations
    localparam  n = 6'b100000;
    localparam  mask = 32'hffffffff;
    
    // Stub signals
    reg  [31:0] last$d;
    wire  [31:0] last$q;
    reg  last$clock;
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
    top$last last(
        .d(last$d),
        .q(last$q),
        .clock(last$clock)
    );
    top$at_or_below_last at_or_below_last(
        .d(at_or_below_last$d),
        .q(at_or_below_last$q),
        .clock(at_or_below_last$clock)
    );
    
    // Update code
    always @(*) begin
        last$clock = clock;
        at_or_below_last$clock = clock;
        last$d = last$q;
        at_or_below_last$d = at_or_below_last$q;
        above_last = requests & (~at_or_below_last$q);
        both = (((requests) & 64'hffffffffffffffff) << n) | ((above_last) & 64'hffffffffffffffff);
        both_less = both - 32'h1;
        lowest = both & (~both_less);
        upto = both ^ both_less;
        if (hold) begin
            grant = last$q;
            next_at_or_below = (last$q << 32'h1) - 32'h1;
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
        last_grant = last$q;
        if (advance) begin
            last$d = grant & mask;
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


module top$last(d,q,clock);
    
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
          
endmodule // top$last
