//! Four f64 lanes, for the row kernels of the fast removal.
//!
//! Every operation is the scalar operation applied lane by lane
//! (`std::array::from_fn`), which the compiler turns into one SIMD
//! instruction (two SSE2 instructions on the x86-64 baseline, one AVX2
//! instruction where the row kernels are compiled for it). Each lane rounds
//! exactly as the scalar code does: Rust never fuses a product and a sum, and
//! a select is a bitwise choice. Masks hold all ones (true) or zeros per lane.

use std::ops::{Add, BitAnd, BitOr, Div, Mul, Neg, Not, Sub};

/// The lane count.
pub(crate) const W: usize = 4;

/// Four f64 values.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct F(pub [f64; W]);

/// Four booleans as all-ones or all-zeros words.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct M(pub [u64; W]);

impl F {
    #[inline(always)]
    pub fn splat(x: f64) -> F {
        F([x; W])
    }
    #[inline(always)]
    pub fn load(s: &[f64], at: usize) -> F {
        let a: &[f64; W] = s[at..at + W].try_into().expect("W lanes");
        F(*a)
    }
    #[inline(always)]
    pub fn store(self, s: &mut [f64], at: usize) {
        s[at..at + W].copy_from_slice(&self.0);
    }
    #[inline(always)]
    fn map(self, f: impl Fn(f64) -> f64) -> F {
        F(std::array::from_fn(|i| f(self.0[i])))
    }
    #[inline(always)]
    fn zip(self, o: F, f: impl Fn(f64, f64) -> f64) -> F {
        F(std::array::from_fn(|i| f(self.0[i], o.0[i])))
    }
    #[inline(always)]
    fn test(self, o: F, f: impl Fn(f64, f64) -> bool) -> M {
        M(std::array::from_fn(|i| {
            if f(self.0[i], o.0[i]) { u64::MAX } else { 0 }
        }))
    }
    #[inline(always)]
    pub fn abs(self) -> F {
        self.map(f64::abs)
    }
    #[inline(always)]
    pub fn sqrt(self) -> F {
        self.map(f64::sqrt)
    }
    /// `f64::min`, lane by lane (the scalar kernels' `min`).
    #[inline(always)]
    pub fn min(self, o: F) -> F {
        self.zip(o, f64::min)
    }
    /// `f64::max`, lane by lane.
    #[inline(always)]
    pub fn max(self, o: F) -> F {
        self.zip(o, f64::max)
    }
    #[inline(always)]
    pub fn copysign(self, sign: F) -> F {
        self.zip(sign, f64::copysign)
    }
    #[inline(always)]
    pub fn lt(self, o: F) -> M {
        self.test(o, |a, b| a < b)
    }
    #[inline(always)]
    pub fn le(self, o: F) -> M {
        self.test(o, |a, b| a <= b)
    }
    #[inline(always)]
    pub fn gt(self, o: F) -> M {
        self.test(o, |a, b| a > b)
    }
    #[inline(always)]
    pub fn ge(self, o: F) -> M {
        self.test(o, |a, b| a >= b)
    }
    #[inline(always)]
    pub fn eq(self, o: F) -> M {
        self.test(o, |a, b| a == b)
    }
}

impl M {
    #[inline(always)]
    pub fn splat(b: bool) -> M {
        M([if b { u64::MAX } else { 0 }; W])
    }
    #[inline(always)]
    pub fn any(self) -> bool {
        self.0.iter().fold(0, |a, &b| a | b) != 0
    }
    #[inline(always)]
    pub fn lane(self, i: usize) -> bool {
        self.0[i] != 0
    }
    /// `a` where the mask is set, else `b`: a bitwise choice.
    #[inline(always)]
    pub fn select(self, a: F, b: F) -> F {
        F(std::array::from_fn(|i| {
            f64::from_bits((a.0[i].to_bits() & self.0[i]) | (b.0[i].to_bits() & !self.0[i]))
        }))
    }
}

macro_rules! binop {
    ($tr:ident, $f:ident, $op:tt) => {
        impl $tr for F {
            type Output = F;
            #[inline(always)]
            fn $f(self, o: F) -> F {
                self.zip(o, |a, b| a $op b)
            }
        }
    };
}
binop!(Add, add, +);
binop!(Sub, sub, -);
binop!(Mul, mul, *);
binop!(Div, div, /);

impl Neg for F {
    type Output = F;
    #[inline(always)]
    fn neg(self) -> F {
        self.map(|a| -a)
    }
}

impl BitAnd for M {
    type Output = M;
    #[inline(always)]
    fn bitand(self, o: M) -> M {
        M(std::array::from_fn(|i| self.0[i] & o.0[i]))
    }
}

impl BitOr for M {
    type Output = M;
    #[inline(always)]
    fn bitor(self, o: M) -> M {
        M(std::array::from_fn(|i| self.0[i] | o.0[i]))
    }
}

impl Not for M {
    type Output = M;
    #[inline(always)]
    fn not(self) -> M {
        M(std::array::from_fn(|i| !self.0[i]))
    }
}
