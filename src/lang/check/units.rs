//! Physical units of values: powers of metres, seconds and radians. Values are stored in
//! SI (`cm` and `deg` are converted where they are written). A bare number literal is
//! "free": it takes the unit of whatever it meets, so `head.y > 1.2` means metres.

use std::fmt;

/// A unit as exponents of m, s and rad, or a free (unit-less literal) quantity.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Unit {
    /// Power of metres.
    pub len: i8,
    /// Power of seconds.
    pub time: i8,
    /// Power of radians.
    pub angle: i8,
    /// A literal without a unit: adopts the unit of the other operand.
    pub free: bool,
}

impl Unit {
    /// A bare number.
    pub const FREE: Unit = Unit {
        len: 0,
        time: 0,
        angle: 0,
        free: true,
    };
    /// Dimensionless (ratios, cosines, weights of a dot product of unit vectors).
    pub const ONE: Unit = Unit {
        len: 0,
        time: 0,
        angle: 0,
        free: false,
    };
    /// Metres.
    pub const M: Unit = Unit {
        len: 1,
        time: 0,
        angle: 0,
        free: false,
    };
    /// Seconds.
    pub const S: Unit = Unit {
        len: 0,
        time: 1,
        angle: 0,
        free: false,
    };
    /// Radians.
    pub const RAD: Unit = Unit {
        len: 0,
        time: 0,
        angle: 1,
        free: false,
    };

    /// The unit of `a + b`, `a < b`, `min(a, b)`: both must agree unless one is free.
    pub fn unify(self, other: Unit) -> Option<Unit> {
        if self.free {
            Some(other)
        } else if other.free || self == other {
            Some(self)
        } else {
            None
        }
    }

    /// The unit of `a * b`.
    pub fn times(self, other: Unit) -> Unit {
        if self.free && other.free {
            return Unit::FREE;
        }
        Unit {
            len: self.len + other.len,
            time: self.time + other.time,
            angle: self.angle + other.angle,
            free: false,
        }
    }

    /// The unit of `a / b`.
    pub fn per(self, other: Unit) -> Unit {
        self.times(Unit {
            len: -other.len,
            time: -other.time,
            angle: -other.angle,
            ..other
        })
    }

    /// The unit of `a^n`.
    pub fn pow(self, n: i8) -> Unit {
        Unit {
            len: self.len * n,
            time: self.time * n,
            angle: self.angle * n,
            free: self.free,
        }
    }

    /// Half the exponents (for `sqrt`), if they are even.
    pub fn sqrt(self) -> Option<Unit> {
        (self.len % 2 == 0 && self.time % 2 == 0 && self.angle % 2 == 0).then_some(Unit {
            len: self.len / 2,
            time: self.time / 2,
            angle: self.angle / 2,
            free: self.free,
        })
    }

    /// True for free or dimensionless.
    pub fn is_plain(self) -> bool {
        self.len == 0 && self.time == 0 && self.angle == 0
    }

    /// True for free, dimensionless or radians (what `sin` accepts).
    pub fn is_angle_like(self) -> bool {
        self.len == 0 && self.time == 0 && (self.angle == 0 || self.angle == 1)
    }
}

impl fmt::Display for Unit {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.free || self.is_plain() {
            return f.write_str(if self.free { "a plain number" } else { "1" });
        }
        let mut num = Vec::new();
        let mut den = Vec::new();
        for (name, p) in [("m", self.len), ("rad", self.angle), ("s", self.time)] {
            let part = match p.abs() {
                1 => name.to_string(),
                2 => format!("{name}²"),
                3 => format!("{name}³"),
                n => format!("{name}^{n}"),
            };
            match p {
                0 => {}
                p if p > 0 => num.push(part),
                _ => den.push(part),
            }
        }
        let num = if num.is_empty() {
            "1".to_string()
        } else {
            num.join("·")
        };
        if den.is_empty() {
            f.write_str(&num)
        } else {
            write!(f, "{num}/{}", den.join("·"))
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn units_combine() {
        assert_eq!(Unit::FREE.unify(Unit::M), Some(Unit::M));
        assert_eq!(Unit::M.unify(Unit::S), None);
        assert_eq!(Unit::M.per(Unit::S).to_string(), "m/s");
        assert_eq!(Unit::M.per(Unit::S.pow(2)).to_string(), "m/s²");
        assert_eq!(Unit::M.times(Unit::M).sqrt(), Some(Unit::M));
        assert_eq!(Unit::FREE.times(Unit::M), Unit::M);
        assert_eq!(Unit::M.per(Unit::M).to_string(), "1");
    }
}
