//! ms2-mpm (placeholder: being written).
