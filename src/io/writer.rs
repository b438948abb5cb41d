//! Writers for the formats zoovr produces (issue 2: the generator writes
//! zlib-compressed `.vtu`).
