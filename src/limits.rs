//! Bounds on what one command may ask of the machine, checked before anything is allocated
//! (`docs/reliability.md`): a count given on the command line or in a scene is refused with
//! the key, the value and the largest value that fits, instead of running out of memory.

/// Available memory of this machine in bytes (MemAvailable), if known.
pub fn available_memory() -> Option<u64> {
    let text = std::fs::read_to_string("/proc/meminfo").ok()?;
    let line = text.lines().find(|l| l.starts_with("MemAvailable:"))?;
    let kb: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kb * 1024)
}

/// The share of the available memory one command may plan to use.
pub const MEMORY_SHARE: f64 = 0.8;

/// The memory budget in bytes: [`MEMORY_SHARE`] of the available memory (16 GiB when the
/// machine does not say).
pub fn memory_budget() -> f64 {
    MEMORY_SHARE
        * available_memory()
            .map(|b| b as f64)
            .unwrap_or(16.0 * 2f64.powi(30))
}

/// Refuse `count` items of `bytes_each` bytes when they would not fit in the memory budget.
/// `key` names the option or scene key, `what` the items ("runs", "particles").
pub fn check_count(key: &str, count: f64, bytes_each: f64, what: &str) -> anyhow::Result<()> {
    check_count_of(&format!("{key} = {count}"), count, bytes_each, what, "")
}

/// Refuse `count` items of `bytes_each` bytes, like [`check_count`], for a count that
/// several options make together: `asked` names them and their values (e.g. "--angles 0,30
/// and --offsets 1000000000: 2000000002 runs"), `hint` says what to do instead.
pub fn check_count_of(
    asked: &str,
    count: f64,
    bytes_each: f64,
    what: &str,
    hint: &str,
) -> anyhow::Result<()> {
    let budget = memory_budget();
    let need = count * bytes_each;
    if !(need.is_finite() && need <= budget) {
        anyhow::bail!(
            "{asked}: {count:.3e} {what} would need about {:.3} GiB, more than the {:.1} GiB this machine has available; at most {:.0} {what} fit{}",
            need / 2f64.powi(30),
            budget / 2f64.powi(30),
            (budget / bytes_each).floor(),
            if hint.is_empty() { String::new() } else { format!(" ({hint})") }
        );
    }
    Ok(())
}
