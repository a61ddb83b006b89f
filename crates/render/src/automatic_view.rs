//! What the automatic view says of itself: which of
//! [`frame_scene`](crate::frame_scene)'s views it took, and why, in the
//! words `rtgi render` prints.

use rtgi_math::Vec3;

/// Which of [`frame_scene`](crate::frame_scene)'s views was taken, and why; its `Display`
/// is the sentence `rtgi render` prints.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum AutomaticView {
    /// A flat model seen straight on, from `from` (a unit axis).
    Flat {
        /// Where the camera is, from the model: a unit axis.
        from: Vec3,
    },
    /// The three-quarter product shot.
    Product {
        /// The horizontal direction from the model towards the side it is shot from.
        from: Vec3,
        /// Which side of the model that is.
        side: ModelSide,
        /// Why that side.
        reason: SideReason,
    },
    /// The bounds seen straight on from the front (into a box).
    StraightOn {
        /// The direction from the model towards the camera.
        from: Vec3,
    },
    /// From the front and 35 degrees above (into a courtyard).
    FromAbove {
        /// The horizontal direction from the model towards the camera.
        from: Vec3,
    },
    /// From the middle of the bounds (a closed room), looking along `along`.
    Inside {
        /// The direction the camera looks in.
        along: Vec3,
    },
    /// From an upper corner of a closed room, across its floor.
    RoomCorner,
}

/// A side of a model, turned from its front (+Z for a +Y-up model, or its
/// long side for a long model of several materials) about its up.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ModelSide {
    /// The front.
    Front,
    /// A quarter turn from the front: its side towards +X for a +Y-up model.
    Side,
    /// The back.
    Back,
    /// Three quarter turns from the front: its other side.
    OtherSide,
}

/// Why the product shot is taken from the side it is.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum SideReason {
    /// The front: no other side shows more.
    Front,
    /// That side shows more of the model's materials than the front.
    Materials {
        /// Materials that side shows.
        shown: usize,
        /// Materials the front shows.
        front: usize,
    },
    /// A model of one material: that side shows `ratio` times the front's
    /// surface detail (1.5 at least).
    Detail {
        /// That side's detail over the front's.
        ratio: f32,
    },
}

impl std::fmt::Display for AutomaticView {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        const MOST: &str = "which shows the most of the scene's materials";
        match *self {
            AutomaticView::Flat { from } => write!(
                f,
                "straight on from {}: the model is flat (a cut-out or a drawing)",
                crate::up_axis::axis_name(from)
            ),
            AutomaticView::Product { from, side, reason } => {
                write!(
                    f,
                    "a three-quarter shot of the model's {}, from {} and above",
                    side.name(),
                    direction_name(from)
                )?;
                match reason {
                    SideReason::Front => Ok(()),
                    SideReason::Materials { shown, front } => {
                        write!(f, ": it shows {shown} of the model's materials, its front {front}")
                    }
                    SideReason::Detail { ratio } => {
                        // A plain front (flat faces square to the view) shows next to no detail.
                        if ratio < 100.0 {
                            write!(f, ": it shows {ratio:.2} times the surface detail of its front")?;
                        } else {
                            write!(f, ": it shows surface detail where its front shows almost none")?;
                        }
                        write!(f, " (a model of one material is shown from its most detailed side)")
                    }
                }
            }
            AutomaticView::StraightOn { from } => {
                write!(f, "straight into the bounds from {}, {MOST}", direction_name(from))
            }
            AutomaticView::FromAbove { from } => {
                write!(f, "from {} and 35 degrees above, {MOST}", direction_name(from))
            }
            AutomaticView::Inside { along } => {
                write!(f, "from the middle of the scene, looking along {}, {MOST}", direction_name(along))
            }
            AutomaticView::RoomCorner => write!(f, "from an upper corner of the closed room, looking across its floor"),
        }
    }
}

impl ModelSide {
    /// Quarter turns from the front.
    pub(crate) fn quarter(self) -> u32 {
        self as u32
    }

    fn name(self) -> &'static str {
        match self {
            ModelSide::Front => "front",
            ModelSide::Back => "back",
            ModelSide::Side | ModelSide::OtherSide => "side",
        }
    }
}

/// An axis's name (`+X`), or the nearest axis's for a direction off the axes.
fn direction_name(direction: Vec3) -> String {
    let axis = (0..3).max_by(|&a, &b| direction[a].abs().total_cmp(&direction[b].abs())).unwrap_or(2);
    let mut nearest = Vec3::ZERO;
    nearest[axis] = direction[axis].signum();
    crate::up_axis::axis_name(nearest)
}
