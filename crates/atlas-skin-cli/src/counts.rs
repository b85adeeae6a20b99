//! Bounds of the counts given on the command line or in a settings file: each is checked
//! with a clear error before anything is allocated or started, so a typo (or a hostile
//! script) cannot ask for terabytes, a billion poses or 100,000 threads.

/// Largest `--max-influences` (and `max_influences` in `--config`): the glTF writer's.
pub use atlas_skin_io::gltf::MAX_INFLUENCES;
/// Largest `eval --poses` and `eval --anim-frames`.
pub const MAX_EVAL_POSES: usize = 10_000;
/// Largest `eval --worst`.
pub const MAX_WORST_VERTICES: usize = 100_000;
/// Largest `bench --vertices`: about 1 GB of vertex streams.
pub const MAX_BENCH_VERTICES: usize = 10_000_000;
/// Largest `bench --threads`.
pub const MAX_THREADS: usize = 256;
/// Largest `bench --frames`.
pub const MAX_BENCH_FRAMES: usize = 100_000;

/// Most consecutive frames in one timed sample of `bench --batch` (`scripts/bench-vs-ozz`
/// asks for about 0.15 s of frames: 16,000 frames of a 3,000-vertex character on a quiet
/// machine).
pub const MAX_BENCH_BATCH: usize = 100_000;

/// A clap value parser for a whole number in `min..=max`.
pub fn count_between(
    min: usize,
    max: usize,
) -> impl Fn(&str) -> Result<usize, String> + Clone + Send + Sync + 'static {
    move |text| {
        let value: usize = text
            .trim()
            .parse()
            .map_err(|_| format!("{text:?} is not a whole number"))?;
        check_count(value, min, max)
    }
}

/// `value` when it lies in `min..=max`, else an error stating the range.
pub fn check_count(value: usize, min: usize, max: usize) -> Result<usize, String> {
    if (min..=max).contains(&value) {
        Ok(value)
    } else {
        Err(format!("{value} is outside {min}..={max}"))
    }
}

/// A clap value parser for a finite number.
pub fn finite(text: &str) -> Result<f32, String> {
    text.trim()
        .parse::<f32>()
        .ok()
        .filter(|v| v.is_finite())
        .ok_or_else(|| format!("{text:?} is not a finite number"))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn counts_outside_their_range_are_refused() {
        let parse = count_between(1, 10);
        assert_eq!(parse("10"), Ok(10));
        assert!(parse("0").unwrap_err().contains("outside 1..=10"));
        assert!(parse("4294967296000000000000").is_err());
        assert!(parse("-1").is_err());
        assert!(finite("nan").is_err());
        assert_eq!(finite("0.5"), Ok(0.5));
    }
}
