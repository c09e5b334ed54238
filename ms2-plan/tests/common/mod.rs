#![allow(dead_code)]
pub mod planar_arm;
