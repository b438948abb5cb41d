//! Numerics shared by every stage: the one table of tolerances and the exact
//! geometric predicates all combinatorial decisions go through.

pub mod expansion;
pub mod predicates;
pub mod tolerance;
