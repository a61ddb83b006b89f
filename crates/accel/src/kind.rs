use std::fmt;
use std::str::FromStr;

use rtgi_math::Vec3;

use crate::{Accel, LinearScan};

/// The acceleration structures this crate offers, selectable by name.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum AccelKind {
    /// Test every triangle: O(n) per ray.
    Linear,
}

/// Parameters of a build; structures ignore those that do not apply to them.
#[derive(Clone, Debug, PartialEq)]
pub struct BuildParams {
    /// Most triangles in a leaf.
    pub max_leaf_size: usize,
}

impl Default for BuildParams {
    fn default() -> Self {
        Self { max_leaf_size: 4 }
    }
}

/// An accelerator name that is not one of [`AccelKind::ALL`].
#[derive(Clone, Debug, thiserror::Error)]
#[error("unknown acceleration structure '{name}' (expected one of: {expected})")]
pub struct UnknownAccel {
    pub name: String,
    pub expected: String,
}

impl AccelKind {
    /// Every variant, in the order tables list them.
    pub const ALL: &'static [AccelKind] = &[AccelKind::Linear];

    /// The name used on command lines and in tables.
    pub fn name(self) -> &'static str {
        match self {
            AccelKind::Linear => "linear",
        }
    }

    /// Builds this structure over `triangles`; hits name triangles by their index here.
    pub fn build(self, triangles: &[[Vec3; 3]], _params: &BuildParams) -> Box<dyn Accel> {
        match self {
            AccelKind::Linear => Box::new(LinearScan::new(triangles)),
        }
    }
}

impl fmt::Display for AccelKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for AccelKind {
    type Err = UnknownAccel;

    fn from_str(name: &str) -> Result<Self, Self::Err> {
        Self::ALL.iter().copied().find(|k| k.name() == name).ok_or_else(|| UnknownAccel {
            name: name.to_owned(),
            expected: Self::ALL.iter().map(|k| k.name()).collect::<Vec<_>>().join(", "),
        })
    }
}
