//! Winged-edge projection of convex cells into regions (issue 6).
