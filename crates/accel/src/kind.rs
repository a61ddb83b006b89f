use rtgi_math::Vec3;

use crate::{Accel, Bvh, Bvh4, Bvh8, Intersector, LinearScan, SplitMethod, Traversal};

/// The acceleration structures this crate offers, selectable by name.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum AccelKind {
    /// Test every triangle: O(n) per ray.
    Linear,
    /// BVH split at the median primitive along the longest axis.
    ObjectMedian,
    /// BVH split at the middle of the longest axis.
    SpatialMedian,
    /// BVH split by the binned surface area heuristic.
    Sah,
    /// BVH split by the surface area heuristic over all centroid positions.
    SahSweep,
    /// Binned SAH BVH collapsed to four children a node, traversed with SIMD.
    Bvh4,
    /// Binned SAH BVH collapsed to eight children a node, traversed with SIMD.
    Bvh8,
}

/// Parameters of a build; structures ignore those that do not apply to them.
#[derive(Clone, Debug, PartialEq)]
pub struct BuildParams {
    /// Most triangles in a leaf (a leaf may hold fewer when the SAH says so).
    pub max_leaf_size: usize,
    /// Bins per axis of the binned SAH build (2 to 256).
    pub sah_bins: usize,
    /// Cost of a traversal step relative to one ray/triangle test, for the SAH.
    pub traversal_cost: f32,
    /// The ray/triangle test every query uses.
    pub intersector: Intersector,
    /// The slab test of BVH traversal.
    pub traversal: Traversal,
}

impl Default for BuildParams {
    fn default() -> Self {
        Self {
            max_leaf_size: 4,
            sah_bins: 16,
            traversal_cost: 1.0,
            intersector: Intersector::default(),
            traversal: Traversal::default(),
        }
    }
}

impl AccelKind {
    /// Every variant, in the order tables list them.
    pub const ALL: &'static [AccelKind] = &[
        AccelKind::Linear,
        AccelKind::ObjectMedian,
        AccelKind::SpatialMedian,
        AccelKind::Sah,
        AccelKind::SahSweep,
        AccelKind::Bvh4,
        AccelKind::Bvh8,
    ];

    /// The name used on command lines and in tables.
    pub fn name(self) -> &'static str {
        match self {
            AccelKind::Linear => "linear",
            AccelKind::Bvh4 => "bvh4",
            AccelKind::Bvh8 => "bvh8",
            _ => self.split_method().map_or("linear", SplitMethod::name),
        }
    }

    /// Children a node of this variant's tree has: 2 for the binary BVHs,
    /// 4 or 8 for the wide ones, `None` for the linear scan.
    pub fn node_width(self) -> Option<usize> {
        match self {
            AccelKind::Linear => None,
            AccelKind::Bvh4 => Some(4),
            AccelKind::Bvh8 => Some(8),
            _ => Some(2),
        }
    }

    /// The BVH split method of this variant; `None` for the linear scan.
    pub fn split_method(self) -> Option<SplitMethod> {
        match self {
            AccelKind::Linear => None,
            AccelKind::ObjectMedian => Some(SplitMethod::ObjectMedian),
            AccelKind::SpatialMedian => Some(SplitMethod::SpatialMedian),
            AccelKind::Sah => Some(SplitMethod::BinnedSah),
            AccelKind::SahSweep => Some(SplitMethod::SweepSah),
            AccelKind::Bvh4 | AccelKind::Bvh8 => Some(SplitMethod::BinnedSah),
        }
    }

    /// Builds this structure over `triangles`; hits name triangles by their index here.
    pub fn build(self, triangles: &[[Vec3; 3]], params: &BuildParams) -> Box<dyn Accel> {
        match (self, self.split_method()) {
            (AccelKind::Bvh4, Some(method)) => Box::new(Bvh4::new(triangles, method, params)),
            (AccelKind::Bvh8, Some(method)) => Box::new(Bvh8::new(triangles, method, params)),
            (_, Some(method)) => Box::new(Bvh::new(triangles, method, params)),
            (_, None) => Box::new(LinearScan::new(triangles, params.intersector)),
        }
    }
}

rtgi_math::named_choices!(AccelKind, "acceleration structure");

impl AccelKind {
    /// Every variant with a spread of build parameters (leaf sizes 1, 2, 4,
    /// 8 and 16; for the binned SAH also 2 and 32 bins), each with both
    /// intersectors, all with the robust traversal: the configurations that
    /// tests run each case over, so that a new variant is tested as soon as
    /// it is added to [`AccelKind::ALL`]. The exactness contract (see the
    /// crate's documentation) holds for every one of them.
    pub fn all_configurations() -> Vec<(AccelKind, BuildParams)> {
        let mut configurations = Vec::new();
        for &intersector in Intersector::ALL {
            let base = BuildParams { intersector, ..BuildParams::default() };
            for &kind in Self::ALL {
                if kind.split_method().is_none() {
                    configurations.push((kind, base.clone()));
                    continue;
                }
                for max_leaf_size in [1, 2, 4, 8, 16] {
                    configurations.push((kind, BuildParams { max_leaf_size, ..base.clone() }));
                }
                if kind == AccelKind::Sah {
                    for sah_bins in [2, 32] {
                        configurations.push((kind, BuildParams { sah_bins, ..base.clone() }));
                    }
                }
            }
        }
        configurations
    }
}
