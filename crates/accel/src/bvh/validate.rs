//! Structural checks of a built hierarchy.

use super::Bvh;

impl Bvh {
    /// Checks the invariants of the tree and returns the first violation:
    /// every triangle that can be hit is in exactly one leaf, every child's
    /// box lies inside its parent's, every leaf's box holds its triangles,
    /// and every node is reachable exactly once.
    pub fn validate(&self) -> Result<(), String> {
        let hittable = self.triangle_ids.len();
        if self.nodes.is_empty() {
            return if hittable == 0 { Ok(()) } else { Err(format!("{hittable} triangles but no nodes")) };
        }
        let mut seen_triangle = vec![false; hittable];
        let mut seen_node = vec![false; self.nodes.len()];
        let mut stack = vec![(0usize, 0usize)];
        while let Some((index, depth)) = stack.pop() {
            if std::mem::replace(&mut seen_node[index], true) {
                return Err(format!("node {index} is reachable twice"));
            }
            if depth > self.stats.depth {
                return Err(format!("node {index} lies deeper ({depth}) than the recorded depth {}", self.stats.depth));
            }
            let node = &self.nodes[index];
            let bounds = node.bounds();
            if node.is_leaf() {
                let range = node.first() as usize..(node.first() + node.count()) as usize;
                if range.end > hittable {
                    return Err(format!("leaf {index} refers past the last triangle"));
                }
                for i in range {
                    if std::mem::replace(&mut seen_triangle[i], true) {
                        return Err(format!("triangle slot {i} is in two leaves"));
                    }
                    if !self.triangles[i].iter().all(|&v| bounds.contains_point(v.into())) {
                        return Err(format!("leaf {index} does not contain its triangle {}", self.triangle_ids[i]));
                    }
                }
            } else {
                for child in [node.first() as usize, node.first() as usize + 1] {
                    let Some(c) = self.nodes.get(child) else {
                        return Err(format!("node {index} has child {child} past the end"));
                    };
                    if !bounds.contains_box(&c.bounds()) {
                        return Err(format!("child {child} is not inside its parent {index}"));
                    }
                    stack.push((child, depth + 1));
                }
            }
        }
        if let Some(missing) = seen_triangle.iter().position(|s| !s) {
            return Err(format!("triangle {} is in no leaf", self.triangle_ids[missing]));
        }
        if let Some(unused) = seen_node.iter().position(|s| !s) {
            return Err(format!("node {unused} is unreachable"));
        }
        let mut ids = self.triangle_ids.clone();
        ids.sort_unstable();
        if ids.windows(2).any(|w| w[0] == w[1]) {
            return Err("a triangle appears twice".into());
        }
        Ok(())
    }
}
