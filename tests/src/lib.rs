pub mod checks;
pub mod geometry;
pub mod reference;
pub mod self_intersect;
pub mod topology;
pub mod volumes;
