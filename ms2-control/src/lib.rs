//! ms2-control (placeholder: being written).
