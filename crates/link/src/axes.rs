//! One value per axis of a board, as the frames carry them.

use core::fmt;
use core::ops::Deref;
use serde::de::{Error, SeqAccess, Visitor};
use serde::ser::SerializeSeq;
use serde::{Deserialize, Deserializer, Serialize, Serializer};

/// The most axes a frame carries: the paper's Excalibur drives three
/// Cartesian axes.
pub const MAX_AXES: usize = 3;

/// One value per axis (axis 0 is x), for 1 to [`MAX_AXES`] axes. On the
/// wire it is the count and then each value, so a one-axis board pays one
/// byte for it. Indexing reads an axis: `a[2]` is z.
///
/// # Examples
///
/// ```
/// use twoport_link::Axes;
/// let duty = Axes::new([120i16, -40, 0]).unwrap();
/// assert_eq!((duty.len(), duty[1]), (3, -40));
/// let one = Axes::one(7u32);
/// assert_eq!(one.as_slice(), &[7]);
/// // No axes, or more than a frame carries, is no value.
/// assert!(Axes::<u8>::from_slice(&[]).is_none());
/// assert!(Axes::from_slice(&[1u8, 2, 3, 4]).is_none());
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Axes<T> {
    len: u8,
    /// The values; the slots past `len` hold a copy of axis 0, so that two
    /// equal values compare equal.
    v: [T; MAX_AXES],
}

impl<T: Copy> Axes<T> {
    /// One axis.
    pub const fn one(x: T) -> Self {
        Axes {
            len: 1,
            v: [x; MAX_AXES],
        }
    }

    /// `N` axes; `None` for none or more than [`MAX_AXES`].
    pub fn new<const N: usize>(xs: [T; N]) -> Option<Self> {
        Self::from_slice(&xs)
    }

    /// The axes of `xs`; `None` for none or more than [`MAX_AXES`].
    pub fn from_slice(xs: &[T]) -> Option<Self> {
        let (&first, _) = xs.split_first()?;
        if xs.len() > MAX_AXES {
            return None;
        }
        let mut v = [first; MAX_AXES];
        v[..xs.len()].copy_from_slice(xs);
        Some(Axes {
            len: xs.len() as u8,
            v,
        })
    }

    /// The values, one per axis.
    pub fn as_slice(&self) -> &[T] {
        &self.v[..self.len as usize]
    }

    /// `N` values, or `None` when there are not exactly `N` axes.
    pub fn to_array<const N: usize>(&self) -> Option<[T; N]> {
        self.as_slice().try_into().ok()
    }

    /// Each value through `f`.
    pub fn map<U: Copy>(&self, mut f: impl FnMut(T) -> U) -> Axes<U> {
        Axes {
            len: self.len,
            v: self.v.map(&mut f),
        }
    }
}

impl<T: Copy + Default> Default for Axes<T> {
    /// One axis of the default value.
    fn default() -> Self {
        Axes::one(T::default())
    }
}

impl<T> Deref for Axes<T> {
    type Target = [T];
    fn deref(&self) -> &[T] {
        &self.v[..self.len as usize]
    }
}

impl<T: Serialize> Serialize for Axes<T> {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        let mut seq = s.serialize_seq(Some(self.len()))?;
        for x in self.iter() {
            seq.serialize_element(x)?;
        }
        seq.end()
    }
}

impl<'de, T: Deserialize<'de> + Copy> Deserialize<'de> for Axes<T> {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct Seq<T>(core::marker::PhantomData<T>);
        impl<'de, T: Deserialize<'de> + Copy> Visitor<'de> for Seq<T> {
            type Value = Axes<T>;
            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                write!(f, "1 to {MAX_AXES} axes")
            }
            fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<Axes<T>, A::Error> {
                if seq.size_hint().is_some_and(|n| n == 0 || n > MAX_AXES) {
                    return Err(A::Error::invalid_length(
                        seq.size_hint().unwrap_or(0),
                        &self,
                    ));
                }
                let first: T = seq
                    .next_element()?
                    .ok_or_else(|| A::Error::invalid_length(0, &self))?;
                let mut a = Axes::one(first);
                while let Some(x) = seq.next_element()? {
                    if a.len() == MAX_AXES {
                        return Err(A::Error::invalid_length(MAX_AXES + 1, &self));
                    }
                    a.v[a.len()] = x;
                    a.len += 1;
                }
                Ok(a)
            }
        }
        d.deserialize_seq(Seq(core::marker::PhantomData))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_trips_each_count_and_refuses_none_or_too_many() {
        let mut buf = [0u8; 64];
        for n in 1..=MAX_AXES {
            let xs = [-5i32, 300, 70_000];
            let a = Axes::from_slice(&xs[..n]).unwrap();
            let bytes = postcard::to_slice(&a, &mut buf).unwrap();
            // The count is one byte, then the values.
            assert_eq!(bytes[0] as usize, n);
            let back: Axes<i32> = postcard::from_bytes(bytes).unwrap();
            assert_eq!(back, a);
            assert_eq!(back.as_slice(), &xs[..n]);
        }
        for bad in [&[0u8][..], &[4, 1, 2, 3, 4]] {
            assert!(postcard::from_bytes::<Axes<u8>>(bad).is_err(), "{bad:?}");
        }
        // One axis of i16: two bytes in all for a small duty.
        let bytes = postcard::to_slice(&Axes::one(5i16), &mut buf).unwrap();
        assert_eq!(bytes.len(), 2);
    }
}
