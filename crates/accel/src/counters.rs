use serde::Serialize;

/// Receives the work a traversal does. The no-op [`NoCounter`] compiles to
/// nothing, so structures write their loops once, generic over this trait.
pub trait Counter {
    /// Called once for each node whose box the ray is tested against.
    fn node_visited(&mut self);
    /// Called with the number of ray/triangle tests just made.
    fn triangles_tested(&mut self, count: u32);
}

/// Counts nothing, at no cost.
#[derive(Clone, Copy, Debug, Default)]
pub struct NoCounter;

impl Counter for NoCounter {
    #[inline(always)]
    fn node_visited(&mut self) {}
    #[inline(always)]
    fn triangles_tested(&mut self, _count: u32) {}
}

/// Work done by the queries of one or many rays.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize)]
pub struct TraversalCounters {
    /// Rays queried.
    pub rays: u64,
    /// Nodes whose boxes were tested, summed over the rays.
    pub nodes_visited: u64,
    /// Ray/triangle tests, summed over the rays.
    pub triangles_tested: u64,
}

impl Counter for TraversalCounters {
    #[inline(always)]
    fn node_visited(&mut self) {
        self.nodes_visited += 1;
    }
    #[inline(always)]
    fn triangles_tested(&mut self, count: u32) {
        self.triangles_tested += count as u64;
    }
}

impl std::ops::AddAssign for TraversalCounters {
    fn add_assign(&mut self, other: Self) {
        self.rays += other.rays;
        self.nodes_visited += other.nodes_visited;
        self.triangles_tested += other.triangles_tested;
    }
}
