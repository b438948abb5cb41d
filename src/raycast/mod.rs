//! The reference software ray caster (issue 4).
