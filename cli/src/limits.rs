//! Limits on sizes that come from the command line or from input files, checked before anything
//! that large is allocated: exceeding one is a clear error rather than an aborted process.

use crate::failure::Failure;

/// Default most rays of one set (`--max-rays`): 2^26 rays are 2 GiB of rays and 1 GiB of hits.
pub const DEFAULT_MAX_RAYS: u64 = 1 << 26;

/// Default most pixels of a rendered image (`--max-pixels`).
pub const DEFAULT_MAX_PIXELS: u64 = 1 << 26;

/// Bytes of memory available now (Linux: MemAvailable of /proc/meminfo), if known.
pub fn available_memory() -> Option<u64> {
    let text = std::fs::read_to_string("/proc/meminfo").ok()?;
    let line = text.lines().find(|l| l.starts_with("MemAvailable:"))?;
    let kib: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    kib.checked_mul(1024)
}

/// Checks `count` items of `what` against `max` (the value of `--{flag}`, a usage error when
/// exceeded) and `bytes_each` times `count` against the memory available (a failure when it does
/// not fit).
pub fn check_count(what: &str, count: u64, flag: &str, max: u64, bytes_each: u64) -> Result<(), Failure> {
    if count > max {
        return Err(Failure::Usage(format!(
            "{count} {what} exceed the limit of {max} (--{flag}; raise it if the machine can hold them)"
        )));
    }
    let bytes = count.saturating_mul(bytes_each);
    if let Some(avail) = available_memory() {
        if bytes > avail {
            return Err(Failure::Run(format!(
                "{count} {what} need {:.1} GiB, more than the {:.1} GiB of memory available",
                gib(bytes),
                gib(avail)
            )));
        }
    }
    Ok(())
}

/// The pixel count of a `width` x `height` image, checked as [`check_count`] does.
pub fn check_image(width: u32, height: u32, what: &str, flag: &str, max: u64, bytes_each: u64) -> Result<u64, Failure> {
    let n = u64::from(width) * u64::from(height);
    check_count(&format!("{what} ({width} x {height})"), n, flag, max, bytes_each)?;
    Ok(n)
}

/// A vector of `n` copies of `value`, reserved fallibly: a failure, not an abort, when the memory
/// is not there.
pub fn try_vec<T: Clone>(n: usize, value: T, what: &str) -> Result<Vec<T>, Failure> {
    let mut v = Vec::new();
    v.try_reserve_exact(n).map_err(|_| {
        Failure::Run(format!(
            "cannot allocate {n} {what} ({:.1} GiB)",
            gib((n as u64).saturating_mul(std::mem::size_of::<T>() as u64))
        ))
    })?;
    v.resize(n, value);
    Ok(v)
}

fn gib(bytes: u64) -> f64 {
    bytes as f64 / (1u64 << 30) as f64
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn over_the_limit_is_a_usage_error_and_over_memory_a_failure() {
        assert!(check_count("rays", 10, "max-rays", 10, 32).is_ok());
        let e = check_count("rays", 11, "max-rays", 10, 32).unwrap_err();
        assert_eq!(e.code(), 2);
        assert!(e.message().contains("--max-rays"), "{e:?}");
        if available_memory().is_some() {
            let e = check_count("rays", 1 << 50, "max-rays", u64::MAX, 32).unwrap_err();
            assert_eq!(e.code(), 1, "{e:?}");
        }
        assert_eq!(check_image(65536, 65536, "rays", "max-rays", DEFAULT_MAX_RAYS, 32).unwrap_err().code(), 2);
        assert!(try_vec(usize::MAX / 64, 0u64, "things").is_err());
        assert_eq!(try_vec(3, 7u8, "things").unwrap(), [7, 7, 7]);
    }
}
