//! How it works: error maxima that never drop a NaN. `f64::max` and `f32::max` return the other
//! operand when one is NaN, so a NaN the GPU writes into an output would vanish from a "largest
//! error" and the comparison would pass; here a value that is not finite is the answer, with where
//! it was, never skipped. Every accuracy figure and every test comparing outputs takes its maxima
//! through these.

/// A value that is not finite, and where it was among the values looked at.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NonFinite {
    /// Its position in the values given.
    pub index: usize,
    /// The value: NaN or an infinity.
    pub value: f64,
}

/// The largest of `values` (0 for none), or the first one that is not finite, with its index.
pub fn worst(values: impl IntoIterator<Item = f64>) -> Result<f64, NonFinite> {
    let mut largest = 0.0f64;
    for (index, value) in values.into_iter().enumerate() {
        if !value.is_finite() {
            return Err(NonFinite { index, value });
        }
        largest = largest.max(value);
    }
    Ok(largest)
}

/// The larger of `a` and `b`, NaN when either is NaN (unlike `f64::max`).
pub fn max_or_nan(a: f64, b: f64) -> f64 {
    if a.is_nan() || b.is_nan() { f64::NAN } else { a.max(b) }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_nan_or_an_infinity_is_the_answer_not_skipped() {
        assert_eq!(worst([0.5, 2.0, 1.0]), Ok(2.0));
        assert_eq!(worst([]), Ok(0.0));
        let nan = worst([0.5, f64::NAN, 3.0]).unwrap_err();
        assert_eq!(nan.index, 1);
        assert!(nan.value.is_nan());
        assert_eq!(worst([1.0, f64::INFINITY]).unwrap_err().index, 1);
        // What `f64::max` does, and why this module exists.
        assert_eq!(0.0f64.max(f64::NAN), 0.0);
        assert!(max_or_nan(0.0, f64::NAN).is_nan() && max_or_nan(f64::NAN, 1.0).is_nan());
        assert_eq!(max_or_nan(1.0, 2.0), 2.0);
    }
}
