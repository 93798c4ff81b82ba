//! Two's-complement integers of 3 and 5 64-bit words: the exact arithmetic of the
//! fixed-point predicates in `predicates` (products of i64, i128 and 3-word values, sums, the
//! sign and a rounded value).

/// Magnitude and sign of an i128.
#[inline(always)]
fn split_i128(x: i128) -> (bool, u128) {
    (x < 0, x.unsigned_abs())
}

/// A 3-word (192-bit) two's-complement integer, little-endian words.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct W3([u64; 3]);

/// A 5-word (320-bit) two's-complement integer, little-endian words.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct W5([u64; 5]);

macro_rules! wide_ops {
    ($t:ident, $n:expr) => {
        impl $t {
            #[inline]
            pub(super) fn add(self, o: Self) -> Self {
                let mut r = [0u64; $n];
                let mut carry = false;
                for i in 0..$n {
                    let (s1, c1) = self.0[i].overflowing_add(o.0[i]);
                    let (s2, c2) = s1.overflowing_add(carry as u64);
                    r[i] = s2;
                    carry = c1 | c2;
                }
                $t(r)
            }
            #[inline]
            fn neg(self) -> Self {
                let mut r = [0u64; $n];
                let mut carry = true;
                for i in 0..$n {
                    let (s, c) = (!self.0[i]).overflowing_add(carry as u64);
                    r[i] = s;
                    carry = c;
                }
                $t(r)
            }
            #[inline]
            pub(super) fn sub(self, o: Self) -> Self {
                self.add(o.neg())
            }
            /// Two's complement of the product of a magnitude (`words` little-endian) and
            /// a sign.
            #[inline]
            fn from_mag(neg: bool, words: [u64; $n]) -> Self {
                let r = $t(words);
                if neg {
                    r.neg()
                } else {
                    r
                }
            }
        }
    };
}
wide_ops!(W3, 3);
wide_ops!(W5, 5);

impl W3 {
    /// Whether the value is zero.
    #[inline]
    pub(super) fn is_zero(self) -> bool {
        self.0 == [0; 3]
    }

    /// Exact `a·b` (|a| < 2^63, |b| < 2^127: the product fits in 190 bits).
    #[inline]
    pub(super) fn mul(a: i64, b: i128) -> W3 {
        let (na, ma) = (a < 0, a.unsigned_abs() as u128);
        let (nb, mb) = split_i128(b);
        let lo = ma * (mb as u64 as u128);
        let hi = ma * (mb >> 64);
        // lo + (hi << 64)
        let w0 = lo as u64;
        let (mid, c) = ((lo >> 64) as u64).overflowing_add(hi as u64);
        let w2 = (hi >> 64) as u64 + c as u64;
        W3::from_mag(na != nb, [w0, mid, w2])
    }
}

impl W5 {
    /// Exact `a·b` (|a| < 2^127, |b| < 2^191 as a two's-complement W3).
    #[inline]
    pub(super) fn mul(a: i128, b: W3) -> W5 {
        let (na, ma) = split_i128(a);
        let nb = (b.0[2] as i64) < 0;
        let mb = if nb { b.neg() } else { b }.0;
        let a_words = [ma as u64, (ma >> 64) as u64];
        let mut r = [0u64; 5];
        for (i, &x) in a_words.iter().enumerate() {
            let mut carry = 0u128;
            for (j, &y) in mb.iter().enumerate() {
                let t = x as u128 * y as u128 + r[i + j] as u128 + carry;
                r[i + j] = t as u64;
                carry = t >> 64;
            }
            let mut k = i + 3;
            while carry != 0 && k < 5 {
                let t = r[k] as u128 + carry;
                r[k] = t as u64;
                carry = t >> 64;
                k += 1;
            }
        }
        W5::from_mag(na != nb, r)
    }

    /// The sign (-1, 0, 1) and the value rounded to a double (a few ulps).
    pub(super) fn sign_and_approx(self) -> (i32, f64) {
        let neg = (self.0[4] as i64) < 0;
        let m = if neg { self.neg() } else { self }.0;
        if m.iter().all(|&w| w == 0) {
            return (0, 0.0);
        }
        let mut v = 0.0;
        for &w in m.iter().rev() {
            v = v * 18446744073709551616.0 + w as f64;
        }
        if neg {
            (-1, -v)
        } else {
            (1, v)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Products at the magnitude limits keep their signs; a zero factor gives zero.
    #[test]
    fn products_at_the_limits() {
        let big = (1i128 << 126) - 1;
        let w = W3::mul(-(1i64 << 62), big);
        assert!((w.0[2] as i64) < 0);
        let back = W5::mul(-big, w);
        assert!(back.sign_and_approx().0 > 0);
        assert!(W3::mul(0, big).is_zero());
        assert!(!w.is_zero());
    }
}
