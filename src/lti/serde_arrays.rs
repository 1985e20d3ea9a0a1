//! Serde for the fixed-size arrays of [`super::Lti`] (as sequences).

#[cfg(feature = "serde")]
pub(super) mod serde_vec {
    use serde::{Deserialize, Deserializer, Serialize, Serializer};
    pub fn serialize<S: Serializer, T: Serialize, const N: usize>(
        v: &[T; N],
        s: S,
    ) -> Result<S::Ok, S::Error> {
        v.as_slice().serialize(s)
    }
    pub fn deserialize<
        'de,
        D: Deserializer<'de>,
        T: Deserialize<'de> + Default + Copy,
        const N: usize,
    >(
        d: D,
    ) -> Result<[T; N], D::Error> {
        super::serde_fixed::<D, T, N>(d)
    }
}

#[cfg(feature = "serde")]
pub(super) mod serde_mat {
    use serde::ser::SerializeSeq;
    use serde::{Deserialize, Deserializer, Serialize, Serializer};
    pub fn serialize<S: Serializer, T: Serialize, const N: usize>(
        m: &[[T; N]; N],
        s: S,
    ) -> Result<S::Ok, S::Error> {
        let mut seq = s.serialize_seq(Some(N))?;
        for row in m {
            seq.serialize_element(row.as_slice())?;
        }
        seq.end()
    }
    pub fn deserialize<
        'de,
        D: Deserializer<'de>,
        T: Deserialize<'de> + Default + Copy,
        const N: usize,
    >(
        d: D,
    ) -> Result<[[T; N]; N], D::Error> {
        struct Row<T, const N: usize>([T; N]);
        impl<'de, T: Deserialize<'de> + Default + Copy, const N: usize> Deserialize<'de> for Row<T, N> {
            fn deserialize<D2: Deserializer<'de>>(d: D2) -> Result<Self, D2::Error> {
                super::serde_fixed::<D2, T, N>(d).map(Row)
            }
        }
        struct V<T, const N: usize>(core::marker::PhantomData<T>);
        impl<'de, T: Deserialize<'de> + Default + Copy, const N: usize> serde::de::Visitor<'de>
            for V<T, N>
        {
            type Value = [[T; N]; N];
            fn expecting(&self, f: &mut core::fmt::Formatter) -> core::fmt::Result {
                write!(f, "{N} rows")
            }
            fn visit_seq<A: serde::de::SeqAccess<'de>>(
                self,
                mut a: A,
            ) -> Result<Self::Value, A::Error> {
                let mut out = [[T::default(); N]; N];
                for (i, row) in out.iter_mut().enumerate() {
                    *row = a
                        .next_element::<Row<T, N>>()?
                        .ok_or_else(|| serde::de::Error::invalid_length(i, &self))?
                        .0;
                }
                Ok(out)
            }
        }
        d.deserialize_seq(V::<T, N>(core::marker::PhantomData))
    }
}

#[cfg(feature = "serde")]
fn serde_fixed<
    'de,
    D: serde::Deserializer<'de>,
    T: serde::Deserialize<'de> + Default + Copy,
    const N: usize,
>(
    d: D,
) -> Result<[T; N], D::Error> {
    struct V<T, const N: usize>(core::marker::PhantomData<T>);
    impl<'de, T: serde::Deserialize<'de> + Default + Copy, const N: usize> serde::de::Visitor<'de>
        for V<T, N>
    {
        type Value = [T; N];
        fn expecting(&self, f: &mut core::fmt::Formatter) -> core::fmt::Result {
            write!(f, "{N} numbers")
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
