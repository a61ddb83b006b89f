//! Structural checks of a built hierarchy.

use std::collections::HashMap;

use rtgi_math::{Aabb, Vec3A};

use super::Bvh;

fn triangle_box(triangle: &[Vec3A; 3]) -> Aabb {
    let [a, b, c] = *triangle;
    Aabb::new(a.min(b).min(c).into(), a.max(b).max(c).into())
}

impl Bvh {
    /// Checks the invariants of the tree and returns the first violation:
    /// every triangle that can be hit is in exactly one leaf, every child's
    /// box lies inside its parent's, every leaf's box holds its triangles,
    /// and every node is reachable exactly once. With spatial splits a
    /// triangle may be in several leaves, whose boxes hold parts of its box
    /// that together reach all of it.
    pub fn validate(&self) -> Result<(), String> {
        let hittable = self.triangle_ids.len();
        if self.nodes.is_empty() {
            return if hittable == 0 { Ok(()) } else { Err(format!("{hittable} triangles but no nodes")) };
        }
        let mut seen_triangle = vec![false; hittable];
        let mut seen_node = vec![false; self.nodes.len()];
        // With spatial splits: the hull of each triangle's parts, and its whole box.
        let mut pieces: HashMap<u32, (Aabb, Aabb)> = HashMap::new();
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
                    if self.spatial_splits {
                        let whole = triangle_box(&self.triangles[i]);
                        let part = Aabb::new(whole.min.max(bounds.min), whole.max.min(bounds.max));
                        let (hull, _) = pieces.entry(self.triangle_ids[i]).or_insert((Aabb::EMPTY, whole));
                        *hull = hull.union(&part);
                    } else if !self.triangles[i].iter().all(|&v| bounds.contains_point(v.into())) {
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
        if self.spatial_splits {
            let hittable_triangles = self.stats.triangles - self.stats.excluded_triangles;
            if pieces.len() != hittable_triangles {
                return Err(format!("{} of {hittable_triangles} triangles are in a leaf", pieces.len()));
            }
            for (id, (hull, whole)) in &pieces {
                if hull != whole {
                    return Err(format!("the leaves of triangle {id} hold only {hull:?} of its box {whole:?}"));
                }
            }
            return Ok(());
        }
        let mut ids = self.triangle_ids.clone();
        ids.sort_unstable();
        if ids.windows(2).any(|w| w[0] == w[1]) {
            return Err("a triangle appears twice".into());
        }
        Ok(())
    }
}
