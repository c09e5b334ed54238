//! ms2-physics (placeholder: being written).
