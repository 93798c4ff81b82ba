//! Process memory figures from /proc (Linux). Shared by the CLI and `benches/delaunay.rs`
//! (included there by path). On other systems the figures are `None`.

/// Peak resident set size of this process in bytes (`VmHWM` of /proc/self/status).
pub fn peak_rss_bytes() -> Option<u64> {
    status_kb("VmHWM:").map(|kb| kb * 1024)
}

/// Current resident set size in bytes (`VmRSS`).
#[allow(dead_code)]
pub fn current_rss_bytes() -> Option<u64> {
    status_kb("VmRSS:").map(|kb| kb * 1024)
}

/// Resets the peak RSS to the current RSS (writes 5 to /proc/self/clear_refs, Linux >= 4.0),
/// so one process can measure the peak of several runs one after the other. Returns whether it
/// worked.
#[allow(dead_code)]
pub fn reset_peak_rss() -> bool {
    std::fs::write("/proc/self/clear_refs", "5").is_ok()
}

fn status_kb(key: &str) -> Option<u64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with(key))?;
    let mut it = line[key.len()..].split_whitespace();
    let v: u64 = it.next()?.parse().ok()?;
    match it.next() {
        Some("kB") | None => Some(v),
        _ => None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    #[cfg(target_os = "linux")]
    fn peak_is_at_least_current_and_sane() {
        // Current first: another test thread may grow the process in between.
        let cur = current_rss_bytes().expect("VmRSS on Linux");
        let peak = peak_rss_bytes().expect("VmHWM on Linux");
        assert!(peak >= cur, "peak {peak} < current {cur}");
        assert!(cur > 100_000, "a running test uses more than 100 kB: {cur}");
    }

    #[test]
    #[cfg(target_os = "linux")]
    fn peak_grows_when_memory_is_touched() {
        let before = peak_rss_bytes().unwrap();
        let v = vec![1u8; 64 << 20];
        std::hint::black_box(&v);
        let after = peak_rss_bytes().unwrap();
        drop(v);
        assert!(after >= before);
        assert!(
            after >= 64 << 20,
            "peak {after} below the 64 MiB just touched"
        );
    }
}
