//! Peak resident memory of the process, per bench row.
//!
//! Linux keeps the high-water mark of the resident set (`VmHWM` in
//! `/proc/self/status`); writing `5` to `/proc/self/clear_refs` resets it
//! to the current resident set (Linux 4.0 and later). A row resets it
//! before its first render and reads it after its last, so the figure is
//! the row's own peak: the mesh and caches already resident plus what the
//! row's renders added. Elsewhere, or where `/proc` refuses, the figure is
//! `None`.

/// Resets the high-water mark (best effort).
pub fn reset_peak() {
    #[cfg(target_os = "linux")]
    {
        let _ = std::fs::write("/proc/self/clear_refs", "5");
    }
}

/// The high-water mark of the resident set since the last reset, in MiB.
pub fn peak_mb() -> Option<f64> {
    #[cfg(target_os = "linux")]
    {
        let status = std::fs::read_to_string("/proc/self/status").ok()?;
        let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
        let kb: f64 = line.split_whitespace().nth(1)?.parse().ok()?;
        Some(kb / 1024.0)
    }
    #[cfg(not(target_os = "linux"))]
    {
        None
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    #[cfg(target_os = "linux")]
    fn peak_follows_a_large_allocation() {
        // The peak is the process's: the other tests of the binary run
        // in parallel and allocate too (tens of MiB), so the allocation
        // here is large against that, and the margins wide.
        reset_peak();
        let before = peak_mb().unwrap();
        let big = vec![1u8; 512 << 20];
        std::hint::black_box(&big);
        let after = peak_mb().unwrap();
        assert!(after >= before + 500.0, "{before} -> {after}");
        drop(big);
        reset_peak();
        let reset = peak_mb().unwrap();
        assert!(reset < after - 256.0, "reset: {after} -> {reset}");
    }
}
