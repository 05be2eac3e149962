//! Compact text summaries of per-frame numbers: min/mean/max and a unicode sparkline, and
//! horizontal bars for rankings. Pure functions over `f32` slices.

const BLOCKS: [char; 8] = ['▁', '▂', '▃', '▄', '▅', '▆', '▇', '█'];

/// Widest sparkline; longer series are averaged into this many buckets.
pub const SPARK_WIDTH: usize = 60;

/// Minimum, mean and maximum of the finite values (None when there are none).
pub fn stats(values: &[f32]) -> Option<(f32, f32, f32)> {
    let finite: Vec<f32> = values.iter().copied().filter(|v| v.is_finite()).collect();
    if finite.is_empty() {
        return None;
    }
    let min = finite.iter().copied().fold(f32::INFINITY, f32::min);
    let max = finite.iter().copied().fold(f32::NEG_INFINITY, f32::max);
    let mean = finite.iter().map(|&v| f64::from(v)).sum::<f64>() / finite.len() as f64;
    Some((min, mean as f32, max))
}

/// A sparkline of `values` (None = frame where the value does not apply, drawn as `·`),
/// at most `width` characters; each character averages a bucket of consecutive frames.
pub fn sparkline(values: &[Option<f32>], width: usize) -> String {
    if values.is_empty() || width == 0 {
        return String::new();
    }
    let buckets = values.len().min(width);
    let bucketed: Vec<Option<f32>> = (0..buckets)
        .map(|b| {
            let lo = b * values.len() / buckets;
            let hi = ((b + 1) * values.len() / buckets).max(lo + 1);
            let vals: Vec<f32> = values[lo..hi]
                .iter()
                .flatten()
                .copied()
                .filter(|v| v.is_finite())
                .collect();
            (!vals.is_empty()).then(|| vals.iter().sum::<f32>() / vals.len() as f32)
        })
        .collect();
    let present: Vec<f32> = bucketed.iter().flatten().copied().collect();
    let lo = present.iter().copied().fold(f32::INFINITY, f32::min);
    let hi = present.iter().copied().fold(f32::NEG_INFINITY, f32::max);
    bucketed
        .iter()
        .map(|v| match v {
            None => '·',
            Some(v) if hi - lo <= f32::EPSILON * hi.abs().max(1.0) => BLOCKS[3],
            Some(v) => {
                let k = ((v - lo) / (hi - lo) * (BLOCKS.len() - 1) as f32).round() as usize;
                BLOCKS[k.min(BLOCKS.len() - 1)]
            }
        })
        .collect()
}

/// A bar of `value / max` of `width` eighth-blocks.
pub fn bar(value: f32, max: f32, width: usize) -> String {
    if max.is_nan() || max <= 0.0 || !value.is_finite() {
        return String::new();
    }
    let eighths = ((value / max).clamp(0.0, 1.0) * (width * 8) as f32).round() as usize;
    let full = eighths / 8;
    let mut s = "█".repeat(full);
    let part = eighths % 8;
    if part > 0 {
        s.push([' ', '▏', '▎', '▍', '▌', '▋', '▊', '▉'][part]);
    }
    s
}

/// A number with 4 significant digits, without exponent for everyday magnitudes.
pub fn num(v: f32) -> String {
    if v == 0.0 {
        return "0".into();
    }
    let a = v.abs();
    if !(1e-3..1e5).contains(&a) {
        return format!("{v:.3e}");
    }
    let decimals = (3 - a.log10().floor() as i32).clamp(0, 6) as usize;
    format!("{v:.decimals$}")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn stats_skip_non_finite() {
        assert_eq!(stats(&[1.0, 3.0, f32::NAN, 2.0]), Some((1.0, 2.0, 3.0)));
        assert_eq!(stats(&[]), None);
    }

    #[test]
    fn sparkline_spans_the_blocks() {
        let v: Vec<Option<f32>> = (0..8).map(|i| Some(i as f32)).collect();
        assert_eq!(sparkline(&v, 60), "▁▂▃▄▅▆▇█");
        let flat = vec![Some(2.0); 5];
        assert_eq!(sparkline(&flat, 60), "▄▄▄▄▄");
        assert_eq!(sparkline(&[Some(0.0), None, Some(1.0)], 60), "▁·█");
    }

    #[test]
    fn sparkline_buckets_long_series() {
        let v: Vec<Option<f32>> = (0..200).map(|i| Some(i as f32)).collect();
        let s = sparkline(&v, 60);
        assert_eq!(s.chars().count(), 60);
        assert!(s.starts_with('▁') && s.ends_with('█'));
    }

    #[test]
    fn bars_and_numbers() {
        assert_eq!(bar(1.0, 1.0, 4), "████");
        assert_eq!(bar(0.5, 1.0, 4), "██");
        assert_eq!(bar(1.0, 0.0, 4), "");
        assert_eq!(num(1.23456), "1.235");
        assert_eq!(num(0.0123456), "0.01235");
        assert_eq!(num(123.456), "123.5");
        assert_eq!(num(0.0), "0");
        assert_eq!(num(2e-5), "2.000e-5");
    }
}
