//! A set of [`Effect`]s, one bit per effect: what a plan simulates, what the
//! user forces on or off, and which loop the renderer runs. Its operations are
//! `const`, so that the specialised render loops can be chosen and checked at
//! compile time from the same type the planner speaks.

use std::fmt;

use serde::Serialize;

use crate::effects::Effect;

#[derive(Clone, Copy, Default, PartialEq, Eq, Hash)]
/// A set of [`Effect`]s, one bit each, with `const` operations so that sets can be computed and checked at compile time.
pub struct EffectSet(u16);

// Every effect must have a bit of its own, and its place in `Effect::ALL` is that bit.
const _: () = {
    assert!(Effect::ALL.len() <= u16::BITS as usize);
    let mut i = 0;
    while i < Effect::ALL.len() {
        assert!(Effect::ALL[i] as usize == i, "Effect::ALL must list the effects in declaration order");
        i += 1;
    }
};

impl EffectSet {
    /// The set of no effect.
    pub const EMPTY: EffectSet = EffectSet(0);
    /// The set of every effect.
    pub const ALL: EffectSet = EffectSet::of(Effect::ALL);

    const fn bit(effect: Effect) -> u16 {
        1 << effect as u16
    }

    /// The set of the effects listed.
    pub const fn of(effects: &[Effect]) -> EffectSet {
        let mut bits = 0;
        let mut i = 0;
        while i < effects.len() {
            bits |= EffectSet::bit(effects[i]);
            i += 1;
        }
        EffectSet(bits)
    }

    /// The set as a number, for a const generic parameter (one bit per
    /// effect, in the order of [`Effect::ALL`]).
    pub const fn bits(self) -> u16 {
        self.0
    }

    /// The set whose [`EffectSet::bits`] are `bits`; bits of no effect are dropped.
    pub const fn from_bits(bits: u16) -> EffectSet {
        EffectSet(bits & EffectSet::ALL.0)
    }

    /// Whether `effect` is in the set.
    pub const fn contains(self, effect: Effect) -> bool {
        self.0 & EffectSet::bit(effect) != 0
    }

    /// The set with `effect` added.
    pub const fn with(self, effect: Effect) -> EffectSet {
        EffectSet(self.0 | EffectSet::bit(effect))
    }

    /// Adds `effect`; returns whether it was missing.
    pub fn insert(&mut self, effect: Effect) -> bool {
        let missing = !self.contains(effect);
        *self = self.with(effect);
        missing
    }

    /// Removes `effect`; returns whether it was there.
    pub fn remove(&mut self, effect: Effect) -> bool {
        let present = self.contains(effect);
        self.0 &= !EffectSet::bit(effect);
        present
    }

    /// The effects in either set.
    pub const fn union(self, other: EffectSet) -> EffectSet {
        EffectSet(self.0 | other.0)
    }

    /// The effects in both sets.
    pub const fn intersection(self, other: EffectSet) -> EffectSet {
        EffectSet(self.0 & other.0)
    }

    /// The effects of `self` that are not in `other`.
    pub const fn difference(self, other: EffectSet) -> EffectSet {
        EffectSet(self.0 & !other.0)
    }

    /// Whether the set holds no effect.
    pub const fn is_empty(self) -> bool {
        self.0 == 0
    }

    /// Number of effects in the set.
    pub const fn len(self) -> usize {
        self.0.count_ones() as usize
    }

    /// The effects of the set, in the order of [`Effect::ALL`].
    pub fn iter(self) -> impl Iterator<Item = Effect> {
        Effect::ALL.iter().copied().filter(move |&effect| self.contains(effect))
    }
}

impl FromIterator<Effect> for EffectSet {
    fn from_iter<I: IntoIterator<Item = Effect>>(effects: I) -> EffectSet {
        effects.into_iter().fold(EffectSet::EMPTY, EffectSet::with)
    }
}

impl fmt::Debug for EffectSet {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_set().entries(self.iter().map(Effect::name)).finish()
    }
}

impl fmt::Display for EffectSet {
    /// The effects' names separated by commas, or `none`.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.is_empty() {
            return f.write_str("none");
        }
        let names: Vec<&str> = self.iter().map(Effect::name).collect();
        f.write_str(&names.join(", "))
    }
}

impl Serialize for EffectSet {
    /// As the list of the effects' names.
    fn serialize<S: serde::Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        serializer.collect_seq(self.iter().map(Effect::name))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn set_operations() {
        let mut set = EffectSet::of(&[Effect::Glossy, Effect::Alpha]);
        assert!(set.contains(Effect::Glossy) && set.contains(Effect::Alpha) && !set.contains(Effect::Textures));
        assert_eq!(set.iter().collect::<Vec<_>>(), vec![Effect::Glossy, Effect::Alpha]);
        assert!(set.insert(Effect::Textures) && !set.insert(Effect::Textures));
        assert!(set.remove(Effect::Glossy) && !set.remove(Effect::Glossy));
        assert_eq!(set, [Effect::Alpha, Effect::Textures].into_iter().collect());
        assert_eq!(EffectSet::ALL.len(), Effect::ALL.len());
        assert_eq!(EffectSet::ALL.difference(set).len(), Effect::ALL.len() - 2);
        assert_eq!(EffectSet::from_bits(u16::MAX), EffectSet::ALL);
        assert_eq!(EffectSet::from_bits(set.bits()), set);
        assert_eq!(format!("{set}"), "textures, alpha");
        assert_eq!(format!("{}", EffectSet::EMPTY), "none");
    }
}
