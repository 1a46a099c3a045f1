//! The on-chip cache in front of the external memory: a line is one block of the
//! layout (one burst), set-associative with 1 to 8 ways or fully associative,
//! replacing by LRU or by FIFO (the cheap one: a set's fill pointer is its only
//! state, no per-hit update, so a hit writes nothing; Hennessy & Patterson,
//! "Computer Architecture", 5th ed., §B.1 compares the two and random). The set of
//! block `b` is `b mod sets`: consecutive block ids are neighbouring subtrees of
//! one band, which a coherent query stream reads together, so they go to different
//! sets.
//!
//! [`Cache::lookup`] and [`Cache::fill`] are separate because in the hardware a
//! miss is filled only when its burst has arrived (the cycle model, `sim`);
//! [`Cache::access`] is both at once, as the trace model uses it.

/// Replacement policy.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Policy {
    /// Least recently used: a hit makes the line the newest.
    Lru,
    /// First in, first out: the oldest fill goes, hits change nothing.
    Fifo,
}

impl Policy {
    pub const ALL: [Policy; 2] = [Policy::Lru, Policy::Fifo];
    pub fn name(self) -> &'static str {
        match self {
            Policy::Lru => "LRU",
            Policy::Fifo => "FIFO",
        }
    }
}

/// A cache's shape.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct CacheConfig {
    /// Lines (blocks held).
    pub lines: usize,
    /// Ways per set; `None` is fully associative (one set of every line).
    pub ways: Option<usize>,
    pub policy: Policy,
}

impl CacheConfig {
    /// "4-way", "fully assoc.".
    pub fn ways_name(&self) -> String {
        match self.ways {
            Some(1) => "direct-mapped".into(),
            Some(w) => format!("{w}-way"),
            None => "fully assoc.".into(),
        }
    }

    /// "4-way LRU", "direct-mapped" (one way: nothing to replace by).
    pub fn name(&self) -> String {
        match self.ways {
            Some(1) => self.ways_name(),
            _ => format!("{} {}", self.ways_name(), self.policy.name()),
        }
    }
}

const EMPTY: u32 = u32::MAX;

/// One cache's state.
pub enum Cache {
    /// `tags[set * ways ..][..ways]`, newest (LRU: most recently used) first.
    Sets {
        ways: usize,
        sets: usize,
        policy: Policy,
        tags: Vec<u32>,
    },
    /// Every line in one list, newest first (a doubly linked list over the lines,
    /// indexed by block id, so each access is O(1)).
    Full(FullyAssociative),
}

impl Cache {
    /// An empty cache for block ids below `blocks`.
    pub fn new(cfg: CacheConfig, blocks: usize) -> Self {
        assert!(cfg.lines >= 1, "a cache of no lines");
        match cfg.ways {
            Some(w) if w < cfg.lines => {
                assert!(
                    cfg.lines.is_multiple_of(w),
                    "{} lines in {w} ways",
                    cfg.lines
                );
                Cache::Sets {
                    ways: w,
                    sets: cfg.lines / w,
                    policy: cfg.policy,
                    tags: vec![EMPTY; cfg.lines],
                }
            }
            _ => Cache::Full(FullyAssociative::new(cfg.lines, blocks, cfg.policy)),
        }
    }

    /// Is `block` held? Under LRU a hit makes it the newest.
    #[inline]
    pub fn lookup(&mut self, block: u32) -> bool {
        match self {
            Cache::Sets {
                ways,
                sets,
                policy,
                tags,
            } => {
                let s = block as usize % *sets;
                let set = &mut tags[s * *ways..(s + 1) * *ways];
                match set.iter().position(|&t| t == block) {
                    Some(i) => {
                        if *policy == Policy::Lru {
                            set[..=i].rotate_right(1);
                        }
                        true
                    }
                    None => false,
                }
            }
            Cache::Full(f) => f.lookup(block),
        }
    }

    /// Bring `block` in as the newest line (evicting the set's last), unless held.
    #[inline]
    pub fn fill(&mut self, block: u32) {
        match self {
            Cache::Sets {
                ways, sets, tags, ..
            } => {
                let s = block as usize % *sets;
                let set = &mut tags[s * *ways..(s + 1) * *ways];
                if !set.contains(&block) {
                    set.rotate_right(1);
                    set[0] = block;
                }
            }
            Cache::Full(f) => f.fill(block),
        }
    }

    /// Look `block` up and fill it on a miss; whether it hit.
    #[inline]
    pub fn access(&mut self, block: u32) -> bool {
        let hit = self.lookup(block);
        if !hit {
            self.fill(block);
        }
        hit
    }
}

const NONE: u32 = u32::MAX;

/// A fully associative cache: the lines form a list, newest at the head.
pub struct FullyAssociative {
    policy: Policy,
    capacity: usize,
    /// Per line: its block, previous (newer) and next (older) line.
    block: Vec<u32>,
    prev: Vec<u32>,
    next: Vec<u32>,
    head: u32,
    tail: u32,
    /// Per block id: its line, or NONE.
    line_of: Vec<u32>,
}

impl FullyAssociative {
    fn new(capacity: usize, blocks: usize, policy: Policy) -> Self {
        FullyAssociative {
            policy,
            capacity,
            block: Vec::with_capacity(capacity.min(blocks)),
            prev: Vec::with_capacity(capacity.min(blocks)),
            next: Vec::with_capacity(capacity.min(blocks)),
            head: NONE,
            tail: NONE,
            line_of: vec![NONE; blocks],
        }
    }

    fn unlink(&mut self, l: u32) {
        let (p, n) = (self.prev[l as usize], self.next[l as usize]);
        if p == NONE {
            self.head = n;
        } else {
            self.next[p as usize] = n;
        }
        if n == NONE {
            self.tail = p;
        } else {
            self.prev[n as usize] = p;
        }
    }

    fn push_head(&mut self, l: u32) {
        self.prev[l as usize] = NONE;
        self.next[l as usize] = self.head;
        if self.head != NONE {
            self.prev[self.head as usize] = l;
        }
        self.head = l;
        if self.tail == NONE {
            self.tail = l;
        }
    }

    fn lookup(&mut self, block: u32) -> bool {
        let l = self.line_of[block as usize];
        if l == NONE {
            return false;
        }
        if self.policy == Policy::Lru && l != self.head {
            self.unlink(l);
            self.push_head(l);
        }
        true
    }

    fn fill(&mut self, block: u32) {
        if self.line_of[block as usize] != NONE {
            return;
        }
        let l = if self.block.len() < self.capacity {
            self.block.push(block);
            self.prev.push(NONE);
            self.next.push(NONE);
            (self.block.len() - 1) as u32
        } else {
            let l = self.tail;
            self.unlink(l);
            self.line_of[self.block[l as usize] as usize] = NONE;
            self.block[l as usize] = block;
            l
        };
        self.line_of[block as usize] = l;
        self.push_head(l);
    }
}
