//! Exact back-to-front visibility order of drawable pieces (issue 5).
