//! Ids of bodies and articulations, and what kind of body an id names.
//!
//! These are plain indices in creation order, engine-neutral: a rigid engine other than this
//! crate's rapier `World` (feature `rapier`) mints ids in the same vocabulary with
//! [`BodyId::from_index`] and [`ArticulationId::from_index`], so code written against ids (task
//! logic, contact reports, renderers) works with either engine.

/// Identifies a rigid body of a world: an actor or an articulation link body.
///
/// Ids are indices in creation order (starting at 0) and stay valid for the life of the world
/// that made them. An id says nothing about which world it belongs to: using an id of one world
/// with another is a logic error that engines report as an unknown id when the index is out of
/// range.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct BodyId(pub(crate) u32);

impl BodyId {
    /// The id of the body with creation index `index` (0 for the first body a world creates).
    ///
    /// For engines that mint ids; users get ids from the world that created the bodies.
    ///
    /// # Panics
    /// If `index` does not fit in 32 bits (ids are stored as `u32`).
    pub fn from_index(index: usize) -> BodyId {
        BodyId(u32::try_from(index).expect("BodyId index must fit in u32"))
    }

    /// The id as an index (creation order, starting at 0).
    pub fn index(self) -> usize {
        self.0 as usize
    }
}

/// Identifies an articulation of a world.
///
/// Ids are indices in creation order (starting at 0) and stay valid for the life of the world.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct ArticulationId(pub(crate) u32);

impl ArticulationId {
    /// The id of the articulation with creation index `index` (0 for the first articulation a
    /// world creates).
    ///
    /// For engines that mint ids; users get ids from the world that created the articulations.
    ///
    /// # Panics
    /// If `index` does not fit in 32 bits (ids are stored as `u32`).
    pub fn from_index(index: usize) -> ArticulationId {
        ArticulationId(u32::try_from(index).expect("ArticulationId index must fit in u32"))
    }

    /// The id as an index (creation order, starting at 0).
    pub fn index(self) -> usize {
        self.0 as usize
    }
}

/// What kind of body a [`BodyId`] names.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BodyKind {
    /// A static actor (including the ground).
    Static,
    /// A dynamic actor.
    Dynamic,
    /// A kinematic actor.
    Kinematic,
    /// A link body of an articulation.
    Link(ArticulationId),
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ids_round_trip_through_indices() {
        assert_eq!(BodyId::from_index(7).index(), 7);
        assert_eq!(ArticulationId::from_index(0).index(), 0);
        assert!(BodyId::from_index(1) < BodyId::from_index(2));
    }

    #[test]
    #[should_panic(expected = "fit in u32")]
    #[cfg(target_pointer_width = "64")]
    fn oversized_index_panics() {
        let _ = BodyId::from_index(u32::MAX as usize + 1);
    }
}
