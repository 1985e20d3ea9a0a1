//! Serde for the fixed-size arrays of [`super::Lti`] (as sequences: a vector
//! of numbers, a matrix of rows). serde implements arrays of a few fixed
//! lengths only, not `[T; N]` for a generic `N`.

#[cfg(feature = "serde")]
use serde::{Deserialize, Deserializer, Serialize, Serializer};

#[cfg(feature = "serde")]
pub(super) mod serde_vec {
    use super::*;
    pub fn serialize<S: Serializer, T: Serialize, const N: usize>(
        v: &[T; N],
        s: S,
    ) -> Result<S::Ok, S::Error> {
        s.collect_seq(v)
    }
    pub fn deserialize<'de, D: Deserializer<'de>, T: Element<'de>, const N: usize>(
        d: D,
    ) -> Result<[T; N], D::Error> {
        fixed::<D, T, N>(d)
    }
}

#[cfg(feature = "serde")]
pub(super) mod serde_mat {
    use super::*;
    pub fn serialize<S: Serializer, T: Serialize, const N: usize>(
        m: &[[T; N]; N],
        s: S,
    ) -> Result<S::Ok, S::Error> {
        s.collect_seq(m.iter().map(|row| row.as_slice()))
    }
    pub fn deserialize<'de, D: Deserializer<'de>, T: Element<'de>, const N: usize>(
        d: D,
    ) -> Result<[[T; N]; N], D::Error> {
        Ok(fixed::<D, Row<T, N>, N>(d)?.map(|row| row.0))
    }
}

/// What an array holds: read from a sequence, a default to start from.
#[cfg(feature = "serde")]
pub(super) trait Element<'de>: Deserialize<'de> + Default + Copy {}

#[cfg(feature = "serde")]
impl<'de, T: Deserialize<'de> + Default + Copy> Element<'de> for T {}

/// A matrix row: `N` numbers.
#[cfg(feature = "serde")]
#[derive(Clone, Copy)]
struct Row<T, const N: usize>([T; N]);

#[cfg(feature = "serde")]
impl<T: Default + Copy, const N: usize> Default for Row<T, N> {
    fn default() -> Self {
        Row([T::default(); N])
    }
}

#[cfg(feature = "serde")]
impl<'de, T: Element<'de>, const N: usize> Deserialize<'de> for Row<T, N> {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        fixed::<D, T, N>(d).map(Row)
    }
}

/// Exactly `N` elements of a sequence.
#[cfg(feature = "serde")]
fn fixed<'de, D: Deserializer<'de>, T: Element<'de>, const N: usize>(
    d: D,
) -> Result<[T; N], D::Error> {
    struct V<T, const N: usize>(core::marker::PhantomData<T>);
    impl<'de, T: Element<'de>, const N: usize> serde::de::Visitor<'de> for V<T, N> {
        type Value = [T; N];
        fn expecting(&self, f: &mut core::fmt::Formatter) -> core::fmt::Result {
            write!(f, "a sequence of {N}")
        }
        fn visit_seq<A: serde::de::SeqAccess<'de>>(
            self,
            mut a: A,
        ) -> Result<Self::Value, A::Error> {
            let mut out = [T::default(); N];
            for (i, v) in out.iter_mut().enumerate() {
                *v = a
                    .next_element()?
                    .ok_or_else(|| serde::de::Error::invalid_length(i, &self))?;
            }
            Ok(out)
        }
    }
    d.deserialize_seq(V::<T, N>(core::marker::PhantomData))
}

#[cfg(all(test, feature = "serde"))]
mod tests {
    use crate::{lti::Discretization, lti::Lti};

    /// A second-order block goes to JSON and back unchanged (its matrix as
    /// rows, its vectors as sequences); a row of the wrong length is refused.
    #[test]
    fn a_block_round_trips() -> Result<(), Box<dyn std::error::Error>> {
        let mut g: Lti<f64, 3> =
            Lti::from_tf(&[1.0, 2.0], &[1.0, 3.0, 2.0], 0.1, Discretization::Zoh)?;
        g.step(1.0);
        let text = serde_json::to_string(&g)?;
        let back: Lti<f64, 3> = serde_json::from_str(&text)?;
        assert_eq!(back, g);
        let v: serde_json::Value = serde_json::from_str(&text)?;
        assert_eq!(v["phi"].as_array().map(Vec::len), Some(3));
        let short = text.replacen("\"gamma\":[", "\"gamma\":[0.5,", 1);
        assert!(serde_json::from_str::<Lti<f64, 3>>(&short).is_err());
        Ok(())
    }
}
