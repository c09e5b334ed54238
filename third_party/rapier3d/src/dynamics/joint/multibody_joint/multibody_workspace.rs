use crate::alloc_prelude::*;
use crate::dynamics::RigidBodyVelocity;
use crate::math::{DVector, Real};

/// A temporary workspace for various updates of the multibody.
#[cfg_attr(feature = "serde-serialize", derive(Serialize, Deserialize))]
#[derive(Clone, Debug)]
pub(crate) struct MultibodyWorkspace {
    pub accs: Vec<RigidBodyVelocity<Real>>,
    pub ndofs_vec: DVector,
    /// For each link, the number of leading generalized coordinates its body Jacobian depends
    /// on: every column at or after this index is zero (see `Multibody::update_jacobian_widths`).
    pub jacobian_widths: Vec<usize>,
    /// The inputs of the last `Multibody::forward_kinematics` (see
    /// `Multibody::forward_kinematics_inputs`); empty when unknown (never serialized, so a
    /// deserialized multibody recomputes its kinematics).
    #[cfg_attr(feature = "serde-serialize", serde(skip))]
    pub forward_kinematics_inputs: Vec<u64>,
    /// Scratch buffer for `Multibody::forward_kinematics_if_changed`.
    #[cfg_attr(feature = "serde-serialize", serde(skip))]
    pub forward_kinematics_scratch: Vec<u64>,
}

impl MultibodyWorkspace {
    /// Create an empty workspace.
    pub fn new() -> Self {
        MultibodyWorkspace {
            accs: Vec::new(),
            ndofs_vec: DVector::zeros(0),
            jacobian_widths: Vec::new(),
            forward_kinematics_inputs: Vec::new(),
            forward_kinematics_scratch: Vec::new(),
        }
    }

    /// Resize the workspace so it is enough for `nlinks` links.
    pub fn resize(&mut self, nlinks: usize, ndofs: usize) {
        self.accs.resize(nlinks, RigidBodyVelocity::zero());
        self.ndofs_vec = DVector::zeros(ndofs)
    }
}
