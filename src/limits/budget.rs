//! The memory budget a frame or a plug-in stage is checked against before anything is
//! allocated, set by [`MEMORY_BUDGET_ENV`].

use crate::error::{Error, Result};

/// The environment variable that sets the memory budget: bytes, or a number with `KiB`,
/// `MiB`, `GiB` or `TiB` (`SHADOWGRAPH_MEMORY_BUDGET=16GiB`).
pub const MEMORY_BUDGET_ENV: &str = "SHADOWGRAPH_MEMORY_BUDGET";

/// The memory budget without [`MEMORY_BUDGET_ENV`]: 4 GiB. wgpu reports no device memory size,
/// so the default is a fixed figure: the memory of the smallest discrete GPUs in common use,
/// and on a software adapter (system memory) a frame that still leaves the machine usable.
/// A frame estimated above it is refused before anything is allocated.
pub const DEFAULT_MEMORY_BUDGET: u64 = 4 << 30;

/// The memory budget: [`MEMORY_BUDGET_ENV`] when set, else [`DEFAULT_MEMORY_BUDGET`].
pub fn memory_budget() -> Result<u64> {
    match std::env::var(MEMORY_BUDGET_ENV) {
        Err(_) => Ok(DEFAULT_MEMORY_BUDGET),
        Ok(v) => parse_bytes(&v).ok_or_else(|| {
            Error::Invalid(format!(
                "{MEMORY_BUDGET_ENV}={v:?}: expected bytes, or a number with KiB, MiB, GiB or TiB"
            ))
        }),
    }
}

/// `"4GiB"`, `"512 MiB"`, `"1.5GiB"` or a plain byte count.
pub fn parse_bytes(s: &str) -> Option<u64> {
    let s = s.trim();
    let split = s
        .find(|c: char| !(c.is_ascii_digit() || c == '.'))
        .unwrap_or(s.len());
    let (number, unit) = s.split_at(split);
    let scale: u64 = match unit.trim() {
        "" | "B" => 1,
        "KiB" => 1 << 10,
        "MiB" => 1 << 20,
        "GiB" => 1 << 30,
        "TiB" => 1 << 40,
        _ => return None,
    };
    let x: f64 = number.parse().ok()?;
    let bytes = x * scale as f64;
    (x.is_finite() && bytes < u64::MAX as f64).then_some(bytes as u64)
}

#[cfg(test)]
mod tests {
    use super::parse_bytes;

    #[test]
    fn budgets_parse() {
        assert_eq!(parse_bytes("4GiB"), Some(4 << 30));
        assert_eq!(parse_bytes("512 MiB"), Some(512 << 20));
        assert_eq!(parse_bytes("1.5GiB"), Some(3 << 29));
        assert_eq!(parse_bytes("1000"), Some(1000));
        assert_eq!(parse_bytes("4GB"), None);
        assert_eq!(parse_bytes("GiB"), None);
        assert_eq!(parse_bytes("-1"), None);
    }
}
