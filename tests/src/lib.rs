pub mod self_intersect;
