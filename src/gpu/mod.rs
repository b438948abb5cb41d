//! wgpu compositor (issue 7).
