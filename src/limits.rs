//! Bounds on what one input line may make demx allocate: a count, a number
//! of types or columns that the machine cannot hold is refused up front
//! (exit 2) instead of growing until the kernel kills the process.

/// Physical memory of this machine in bytes (16 GiB where it cannot be read).
pub fn physical_memory() -> u64 {
    #[cfg(unix)]
    {
        // SAFETY: sysconf only reads system configuration.
        let (pages, size) = unsafe { (libc::sysconf(libc::_SC_PHYS_PAGES), libc::sysconf(libc::_SC_PAGESIZE)) };
        if pages > 0 && size > 0 {
            return (pages as u64).saturating_mul(size as u64);
        }
    }
    16 << 30
}

/// Whether `bytes` (a product of input sizes, in f64 so that it cannot
/// overflow) fits in this machine's memory.
pub fn fits(bytes: f64) -> bool {
    bytes.is_finite() && bytes <= physical_memory() as f64
}

/// `bytes` for a person: "2.1 TB", "512 MB".
pub fn human(bytes: f64) -> String {
    let units = ["B", "kB", "MB", "GB", "TB", "PB", "EB"];
    let mut v = bytes;
    let mut k = 0;
    while v >= 1000.0 && k + 1 < units.len() {
        v /= 1000.0;
        k += 1;
    }
    if v >= 1000.0 {
        format!("{bytes:.1e} B")
    } else {
        format!("{v:.1} {}", units[k])
    }
}

/// "this machine has 16.8 GB of memory", for messages.
pub fn machine() -> String {
    format!("this machine has {} of memory", human(physical_memory() as f64))
}

/// Bytes one particle takes at the least: its columns (~180 B: id, type,
/// mask, x, v, omega, f, torque, radius, mass, density, image) with room for
/// a growing `Vec`'s doubling, before neighbour lists and history.
pub const BYTES_PER_PARTICLE: f64 = 400.0;
