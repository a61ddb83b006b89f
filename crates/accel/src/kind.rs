use crate::{Accel, Bvh, Bvh4, Bvh8, Bvh8Quantised, Intersector, LinearScan, SplitMethod, Traversal, TriangleSource};

/// The acceleration structures this crate offers, selectable by name.
///
/// Their names ([`AccelKind::name`]) are read back by `FromStr`, which
/// also accepts the peers ([`AccelKind::PEERS`]); with the `clap` feature
/// the type is a `clap::ValueEnum` with the same names.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
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
    /// bvh8 with child boxes quantised to one byte a plane: half the node memory.
    Bvh8q,
    /// BVH split by the binned SAH with spatial splits (SBVH): triangles
    /// that straddle a cut are referenced on both sides, so that nodes of
    /// interiors with long walls overlap less.
    Sbvh,
    /// The spatial-split BVH collapsed to eight children a node, traversed with SIMD.
    Sbvh8,
    /// Intel Embree 3, a peer to compare against, not held to the exactness contract.
    ///
    /// Built with the `embree` feature: [`crate::EmbreeBackend`].
    #[cfg(feature = "embree")]
    Embree,
}

/// The axes on which the binned SAH build places its candidate planes.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
pub enum SahAxes {
    /// All three axes, at every bin border: the best split the bins allow.
    #[default]
    All,
    /// Only the longest axis of the node's centroids, at every bin border
    /// (`sah_bins - 1` evenly spaced planes), with no exhaustive sweep of
    /// small nodes: the SAH as taught in the course this toolkit comes
    /// from (`bbvh sah N`), cheaper to build and worse to trace.
    Longest,
}

impl SahAxes {
    /// Every choice, in the order help texts list them.
    pub const ALL: &'static [SahAxes] = &[SahAxes::All, SahAxes::Longest];

    /// The name on command lines and in reports (`all`, `longest`).
    pub fn name(self) -> &'static str {
        match self {
            SahAxes::All => "all",
            SahAxes::Longest => "longest",
        }
    }
}

impl rtgi_math::NamedChoice for SahAxes {
    const KIND: &'static str = "set of SAH axes";
    const ALL: &'static [Self] = SahAxes::ALL;
    fn name(self) -> &'static str {
        SahAxes::name(self)
    }
}

/// Parameters of a build; structures ignore those that do not apply to them.
#[derive(Clone, Debug, PartialEq)]
pub struct BuildParams {
    /// Most triangles in a leaf (a leaf may hold fewer when the SAH says so).
    pub max_leaf_size: usize,
    /// Bins per axis of the binned SAH build (2 to 256).
    pub sah_bins: usize,
    /// Which axes the binned SAH build tries splits on.
    pub sah_axes: SahAxes,
    /// Cost of a traversal step relative to one leaf test, for the SAH: one
    /// ray/triangle test, or for the wide BVHs one test of a block of four
    /// triangles, which they test at once.
    pub traversal_cost: f32,
    /// The ray/triangle test every query uses.
    pub intersector: Intersector,
    /// The slab test of the binary BVHs' traversal (the wide BVHs always use the robust one).
    pub traversal: Traversal,
}

impl BuildParams {
    /// The leaf sizes a build accepts ([`BuildParams::check`]).
    pub const LEAF_SIZES: std::ops::RangeInclusive<usize> = 1..=255;
    /// The bin counts a build accepts ([`BuildParams::check`]); the build clamps others into it.
    pub const SAH_BINS: std::ops::RangeInclusive<usize> = 2..=256;

    /// Whether the parameters are in their ranges: a leaf size in
    /// [`BuildParams::LEAF_SIZES`], a bin count in [`BuildParams::SAH_BINS`]
    /// and a finite traversal cost greater than 0; the error names the
    /// parameter and its range.
    pub fn check(&self) -> Result<(), String> {
        let (leaf, bins) = (Self::LEAF_SIZES, Self::SAH_BINS);
        if !leaf.contains(&self.max_leaf_size) {
            return Err(format!("leaf size {}: expected {} to {}", self.max_leaf_size, leaf.start(), leaf.end()));
        }
        if !bins.contains(&self.sah_bins) {
            return Err(format!("SAH bins {}: expected {} to {}", self.sah_bins, bins.start(), bins.end()));
        }
        if !(self.traversal_cost.is_finite() && self.traversal_cost > 0.0) {
            return Err(format!("traversal cost {}: expected a finite number greater than 0", self.traversal_cost));
        }
        Ok(())
    }
}

/// The SAH's traversal cost for a BVH of `width`-wide nodes, built as a
/// binary tree and collapsed: `2 / width` ([`AccelKind::default_params`]).
fn wide_traversal_cost(width: usize) -> f32 {
    2.0 / width as f32
}

impl Default for BuildParams {
    fn default() -> Self {
        Self {
            max_leaf_size: 4,
            sah_bins: 16,
            sah_axes: SahAxes::All,
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
        AccelKind::Bvh8q,
        AccelKind::Sbvh,
        AccelKind::Sbvh8,
    ];

    /// Backends written by others, measured beside ours but not held to
    /// the exactness contract: they differ from the linear scan at ties and
    /// on grazing rays. Not in [`AccelKind::ALL`] nor in
    /// [`AccelKind::all_configurations`]; empty without the `embree` feature.
    #[cfg(feature = "embree")]
    pub const PEERS: &'static [AccelKind] = &[AccelKind::Embree];
    /// Backends written by others, measured beside ours but not held to
    /// the exactness contract; empty without the `embree` feature.
    #[cfg(not(feature = "embree"))]
    pub const PEERS: &'static [AccelKind] = &[];

    /// Whether this is a peer's backend ([`AccelKind::PEERS`]).
    pub fn is_peer(self) -> bool {
        Self::PEERS.contains(&self)
    }

    /// The name used on command lines and in tables.
    pub fn name(self) -> &'static str {
        match self {
            AccelKind::Linear => "linear",
            AccelKind::Bvh4 => "bvh4",
            AccelKind::Bvh8 => "bvh8",
            AccelKind::Bvh8q => "bvh8q",
            AccelKind::Sbvh8 => "sbvh8",
            #[cfg(feature = "embree")]
            AccelKind::Embree => "embree",
            _ => self.split_method().map_or("linear", SplitMethod::name),
        }
    }

    /// Children a node of this variant's tree has: 2 for the binary BVHs,
    /// 4 or 8 for the wide ones, `None` for the linear scan and peers.
    pub fn node_width(self) -> Option<usize> {
        match self {
            AccelKind::Linear => None,
            AccelKind::Bvh4 => Some(4),
            AccelKind::Bvh8 | AccelKind::Bvh8q | AccelKind::Sbvh8 => Some(8),
            #[cfg(feature = "embree")]
            AccelKind::Embree => None,
            _ => Some(2),
        }
    }

    /// The build parameters this variant is tuned for. The binary BVHs
    /// take [`BuildParams::default`]. The wide ones take leaves of up to 8
    /// triangles (two blocks of four), and their SAH prices a leaf by its
    /// blocks. Their traversal cost is `2 / width`: a quarter for the
    /// eight-wide BVHs, a half for the four-wide (and 1, the binary BVHs'
    /// own, for width 2). The SAH prices the nodes of the binary tree they
    /// are collapsed from, and one wide node takes the place of about
    /// `log2(width)` levels of it and up to `width - 1` of its nodes.
    ///
    /// Counting levels gives `1 / log2(width)`, a third for eight-wide
    /// nodes, which was the default until 2026-11-29; a quarter was
    /// measured better (`rtgi trace`, 1 thread, the two alternating, 9
    /// pairs): the Cornell box's surface rays took 0.889 (0.845-0.902) of the
    /// time, a ray testing 4.1 triangles rather than 6.3 (`--stats`);
    /// the bunny's, the conference room's and Sponza's camera, random and
    /// surface rays, single and in packets, stayed within their spread
    /// (medians 0.994 to 1.017), for 1% (bunny) to 7% (conference room) more
    /// memory. For four-wide nodes 3/8 changed no time, so a half stays.
    ///
    /// Priced by triangles with a traversal cost of 4 (until 2026-11), the
    /// trees traced as fast but took a tenth (bunny) to a sixth
    /// (conference room) more memory: leaves of five were split four and
    /// one, and 23% of the conference room's blocks held a single triangle.
    pub fn default_params(self) -> BuildParams {
        match self.node_width() {
            Some(width) if width > 2 => {
                BuildParams { max_leaf_size: 8, traversal_cost: wide_traversal_cost(width), ..BuildParams::default() }
            }
            _ => BuildParams::default(),
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
            AccelKind::Bvh4 | AccelKind::Bvh8 | AccelKind::Bvh8q => Some(SplitMethod::BinnedSah),
            AccelKind::Sbvh | AccelKind::Sbvh8 => Some(SplitMethod::SpatialSah),
            #[cfg(feature = "embree")]
            AccelKind::Embree => None,
        }
    }

    /// Builds this structure over `triangles`, a soup (`&[[Vec3; 3]]`, an
    /// array or a vector of corners), an [`crate::IndexedMesh`] or any
    /// [`TriangleSource`]; hits name triangles by their index there.
    ///
    /// # Panics
    /// If a peer's build fails (Embree out of memory); [`AccelKind::try_build`]
    /// returns that error instead. Our structures' builds cannot fail.
    pub fn build(self, triangles: &(impl TriangleSource + ?Sized), params: &BuildParams) -> Box<dyn Accel> {
        self.try_build(triangles, params).unwrap_or_else(|error| panic!("{error}"))
    }

    /// [`AccelKind::build`], with the error of a peer's failed build.
    ///
    /// # Errors
    /// If Embree cannot create its device or build its scene.
    pub fn try_build(
        self,
        triangles: &(impl TriangleSource + ?Sized),
        params: &BuildParams,
    ) -> Result<Box<dyn Accel>, BuildError> {
        self.try_build_from_any(&triangles, params)
    }

    /// [`AccelKind::try_build`] for every source at once. Building a
    /// `Box<dyn Accel>` generates code for every structure's queries, and a
    /// generic builder did so again in every crate that built from a source
    /// type of its own: two minutes of compiling per test binary. Builds
    /// read each triangle once or twice, so the virtual call is lost in the
    /// build's time.
    fn try_build_from_any(
        self,
        triangles: &dyn TriangleSource,
        params: &BuildParams,
    ) -> Result<Box<dyn Accel>, BuildError> {
        #[cfg(feature = "embree")]
        if self == AccelKind::Embree {
            return match crate::EmbreeBackend::new(triangles) {
                Ok(backend) => Ok(Box::new(backend)),
                Err(error) => Err(BuildError { variant: self.name(), reason: error.to_string() }),
            };
        }
        Ok(match (self, self.split_method()) {
            (AccelKind::Bvh4, Some(method)) => Box::new(Bvh4::new(triangles, method, params)),
            (AccelKind::Bvh8 | AccelKind::Sbvh8, Some(method)) => Box::new(Bvh8::new(triangles, method, params)),
            (AccelKind::Bvh8q, Some(method)) => Box::new(Bvh8Quantised::new(triangles, method, params)),
            (_, Some(method)) => Box::new(Bvh::new(triangles, method, params)),
            (_, None) => Box::new(LinearScan::new(triangles, params.intersector)),
        })
    }
}

/// Why a structure could not be built; only peers' builds can fail.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct BuildError {
    /// The variant's name.
    pub variant: &'static str,
    /// What went wrong.
    pub reason: String,
}

impl std::fmt::Display for BuildError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "cannot build {}: {}", self.variant, self.reason)
    }
}

impl std::error::Error for BuildError {}

/// What naming `embree` says in a build without the feature.
const EMBREE_NOT_BUILT: &str = "the embree backend is not built in: install Embree 3 (apt install libembree-dev) \
     and build with the embree feature (cargo build --release --features embree)";

impl std::fmt::Display for AccelKind {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// Parses the names of [`AccelKind::ALL`] and [`AccelKind::PEERS`] (as
/// [`rtgi_math::parse_choice`] does, with the peers); `embree` in a build
/// without the feature is an error that says how to get it.
impl std::str::FromStr for AccelKind {
    type Err = String;

    fn from_str(text: &str) -> Result<Self, Self::Err> {
        let choices = || Self::ALL.iter().chain(Self::PEERS).copied();
        if let Some(kind) = choices().find(|kind| kind.name() == text) {
            return Ok(kind);
        }
        if text == "embree" {
            return Err(EMBREE_NOT_BUILT.to_owned());
        }
        let names: Vec<&str> = choices().map(AccelKind::name).collect();
        Err(format!("unknown acceleration structure '{text}' (expected one of: {})", names.join(", ")))
    }
}

impl AccelKind {
    /// Every variant with a spread of build parameters, all with the robust
    /// traversal: with the default intersector, leaf sizes 1, 2, 4, 8 and
    /// 16, the variant's tuned parameters, and for the binned SAH also 2
    /// and 32 bins and the course's SAH; with the other intersectors, leaf
    /// sizes 1, 4 and 16 and the tuned parameters (a sample, so that the
    /// tests' time does not grow with every variant times every knob).
    /// These are the configurations that tests run each case over, so that
    /// a new variant is tested as soon as it is added to
    /// [`AccelKind::ALL`]. The exactness contract (see the crate's
    /// documentation) holds for every one of them.
    pub fn all_configurations() -> Vec<(AccelKind, BuildParams)> {
        let mut configurations = Vec::new();
        for &intersector in Intersector::ALL {
            let base = BuildParams { intersector, ..BuildParams::default() };
            let every_knob = intersector == Intersector::default();
            let leaf_sizes: &[usize] = if every_knob { &[1, 2, 4, 8, 16] } else { &[1, 4, 16] };
            for &kind in Self::ALL {
                if kind.split_method().is_none() {
                    configurations.push((kind, base.clone()));
                    continue;
                }
                for &max_leaf_size in leaf_sizes {
                    configurations.push((kind, BuildParams { max_leaf_size, ..base.clone() }));
                }
                let tuned = BuildParams { intersector, ..kind.default_params() };
                if !configurations.contains(&(kind, tuned.clone())) {
                    configurations.push((kind, tuned));
                }
                if kind == AccelKind::Sah && every_knob {
                    for sah_bins in [2, 32] {
                        configurations.push((kind, BuildParams { sah_bins, ..base.clone() }));
                    }
                    // The course's SAH: a few planes on the longest axis, leaves of one.
                    let course =
                        BuildParams { sah_bins: 5, sah_axes: SahAxes::Longest, max_leaf_size: 1, ..base.clone() };
                    configurations.push((kind, course));
                }
            }
        }
        configurations
    }
}
