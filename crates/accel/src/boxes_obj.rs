//! The boxes of a BVH's levels as an OBJ mesh, for viewers: what
//! `rtgi bvh-boxes` and the course's `bvh export` write.

use std::fmt::Write as _;

use crate::{Accel, AccelKind, BuildParams, Bvh, Bvh4, Bvh8, Vec3};

/// Builds `kind` over `triangles` and writes the boxes of its nodes at
/// `levels` (the root is 0) as OBJ, eight corners and six quads a box and a
/// group `level_N` for each level, so that viewers can show or hide levels
/// and draw them as wireframes; with the number of boxes. `None` when `kind`
/// is not a BVH (it has no boxes).
pub fn boxes_obj(
    kind: AccelKind,
    triangles: &[[Vec3; 3]],
    params: &BuildParams,
    levels: &[usize],
) -> Option<(String, usize)> {
    let method = kind.split_method()?;
    let (boxes, stats) = match kind.node_width() {
        Some(4) => {
            let bvh = Bvh4::new(triangles, method, params);
            (bvh.boxes_at_depths(levels), bvh.build_stats().clone())
        }
        Some(8) => {
            let bvh = Bvh8::new(triangles, method, params);
            (bvh.boxes_at_depths(levels), bvh.build_stats().clone())
        }
        _ => {
            let bvh = Bvh::new(triangles, method, params);
            (bvh.boxes_at_depths(levels), bvh.build_stats().clone())
        }
    };
    let mut obj = format!(
        "# BVH boxes of levels {:?}, {} ({} build, {} nodes, depth {}), written by rtgi\n",
        levels,
        kind,
        method.name(),
        stats.nodes,
        stats.depth
    );
    let mut current_level = None;
    for (index, (level, aabb)) in boxes.iter().enumerate() {
        if current_level != Some(*level) {
            let _ = writeln!(obj, "g level_{level}");
            current_level = Some(*level);
        }
        for corner in 0..8 {
            let pick = |bit: usize, axis: usize| if corner & bit == 0 { aabb.min[axis] } else { aabb.max[axis] };
            let _ = writeln!(obj, "v {} {} {}", pick(1, 0), pick(2, 1), pick(4, 2));
        }
        let base = 8 * index + 1;
        for face in [[0, 2, 3, 1], [4, 5, 7, 6], [0, 1, 5, 4], [2, 6, 7, 3], [0, 4, 6, 2], [1, 3, 7, 5]] {
            let _ = writeln!(obj, "f {} {} {} {}", base + face[0], base + face[1], base + face[2], base + face[3]);
        }
    }
    Some((obj, boxes.len()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_bvh_has_boxes_a_linear_scan_none() {
        let triangles: Vec<[Vec3; 3]> = (0..16)
            .map(|i| {
                let x = i as f32;
                [Vec3::new(x, 0.0, 0.0), Vec3::new(x + 0.5, 1.0, 0.0), Vec3::new(x, 0.0, 1.0)]
            })
            .collect();
        let kind = AccelKind::ObjectMedian;
        let (obj, count) = boxes_obj(kind, &triangles, &kind.default_params(), &[0, 1]).expect("a BVH");
        assert_eq!(count, 3, "the root and its two children");
        assert!(obj.contains("g level_0\n") && obj.contains("g level_1\n"));
        assert_eq!(obj.lines().filter(|l| l.starts_with("v ")).count(), 8 * count);
        assert!(boxes_obj(AccelKind::Linear, &triangles, &AccelKind::Linear.default_params(), &[0]).is_none());
    }
}
