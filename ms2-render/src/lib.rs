//! ms2-render (placeholder: being written).
