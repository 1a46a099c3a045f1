

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
    reg last$clock__xs;
    reg at_or_below_last$clock__xs;
    reg [31:0] last$d__xs;
    reg [31:0] at_or_below_last$d__xs;
    reg [31:0] above_last__xs;
    reg [63:0] both__xs;
    reg [63:0] both_less__xs;
    reg [63:0] lowest__xs;
    reg [63:0] upto__xs;
    reg [31:0] grant__xs;
    reg [31:0] next_at_or_below__xs;
    reg granted__xs;
    reg [31:0] last_grant__xs;
    always @(*) begin
        last$clock__xs = clock;
        at_or_below_last$clock__xs = clock;
        last$d__xs = last$q;
        at_or_below_last$d__xs = at_or_below_last$q;
        above_last__xs = requests & (~at_or_below_last$q);
        both__xs = (((requests) & 64'hffffffffffffffff) << n) | ((above_last__xs) & 64'hffffffffffffffff);
        both_less__xs = both__xs - 32'h1;
        lowest__xs = both__xs & (~both_less__xs);
        upto__xs = both__xs ^ both_less__xs;
        if (hold) begin
            grant__xs = last$q;
            next_at_or_below__xs = (last$q << 32'h1) - 32'h1;
        end
        else begin
            grant__xs = (((lowest__xs) & 32'hffffffff) & mask) | ((lowest__xs >> n) & 32'hffffffff);
            if (upto__xs[n]) begin
                next_at_or_below__xs = ((upto__xs >> n) & 32'hffffffff);
            end
            else begin
                next_at_or_below__xs = ((upto__xs) & 32'hffffffff);
            end
        end
        granted__xs = |requests;
        last_grant__xs = last$q;
        if (advance) begin
            last$d__xs = grant__xs & mask;
            at_or_below_last$d__xs = next_at_or_below__xs & mask;
        end
        last$clock = last$clock__xs;
        at_or_below_last$clock = at_or_below_last$clock__xs;
        last$d = last$d__xs;
        at_or_below_last$d = at_or_below_last$d__xs;
        above_last = above_last__xs;
        both = both__xs;
        both_less = both_less__xs;
        lowest = lowest__xs;
        upto = upto__xs;
        grant = grant__xs;
        next_at_or_below = next_at_or_below__xs;
        granted = granted__xs;
        last_grant = last_grant__xs;
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
