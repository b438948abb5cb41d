//! Exact Williams-Max segment integrals and pre-integration tables (issue 3).
