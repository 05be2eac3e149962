//! Solver knobs: the numeric settings `--knob name=value`, `:run … name=value` and the
//! benchmarks change by name. Each solver lists its knobs once ([`Knob`]: name, meaning,
//! kind, getter, setter); the CLI, the REPL, `bench tasks` and the book's knob table read
//! that list through [`super::Solver`].

/// What values a knob takes; [`check`] refuses the others before the setter runs.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum KnobKind {
    /// A whole number ≥ 0 (steps, iterations).
    Count,
    /// Any finite number (the solver's own check runs when it starts).
    Real,
    /// 0 or 1, with what each means.
    Flag {
        /// What 0 means.
        off: &'static str,
        /// What 1 means.
        on: &'static str,
    },
}

/// One knob of solver settings `C`.
pub struct Knob<C> {
    /// Its name on the command line.
    pub name: &'static str,
    /// What it does, for help and the book.
    pub doc: &'static str,
    /// The values it takes.
    pub kind: KnobKind,
    /// Its value in a configuration (defaults come from the solver's default one).
    pub get: fn(&C) -> f64,
    /// Sets it from a value [`check`] has accepted.
    pub set: fn(&mut C, f64),
}

/// A knob of a configured solver: its description and current value.
#[derive(Clone, Debug, PartialEq)]
pub struct KnobValue {
    /// Its name.
    pub name: &'static str,
    /// What it does.
    pub doc: &'static str,
    /// The values it takes.
    pub kind: KnobKind,
    /// Its value.
    pub value: f64,
}

impl KnobValue {
    /// The value as help text and the book show it (`1000`, `0.01`, `1`).
    pub fn shown(&self) -> String {
        match self.kind {
            KnobKind::Real => format!("{}", self.value as f32),
            KnobKind::Count | KnobKind::Flag { .. } => format!("{}", self.value.round()),
        }
    }
}

/// Whether `value` is one `kind` takes; the message names the knob.
pub fn check(name: &str, kind: KnobKind, value: f64) -> Result<(), String> {
    let whole = value.is_finite() && value >= 0.0 && value.fract() == 0.0 && value <= 1e7;
    match kind {
        KnobKind::Count if !whole => Err(format!("`{name}` must be a whole number, not {value}")),
        KnobKind::Real if !value.is_finite() => Err(format!("`{name}` must be finite")),
        KnobKind::Flag { off, on } if !(value == 0.0 || value == 1.0) => {
            Err(format!("`{name}` is 0 ({off}) or 1 ({on})"))
        }
        _ => Ok(()),
    }
}

/// A knob that is one field of the settings: `knob!(Count, "steps", "DDPM steps", steps)`,
/// `knob!(Real, …)`, `knob!(Flag("off", "on"), …)`.
macro_rules! knob {
    (Count, $name:literal, $doc:expr, $field:ident) => {
        $crate::solve::knobs::Knob {
            name: $name,
            doc: $doc,
            kind: $crate::solve::knobs::KnobKind::Count,
            get: |c| c.$field as f64,
            set: |c, v| c.$field = v as usize,
        }
    };
    (Real, $name:literal, $doc:expr, $field:ident) => {
        $crate::solve::knobs::Knob {
            name: $name,
            doc: $doc,
            kind: $crate::solve::knobs::KnobKind::Real,
            get: |c| c.$field as f64,
            set: |c, v| c.$field = v as _,
        }
    };
    (Flag($off:literal, $on:literal), $name:literal, $doc:expr, $field:ident) => {
        $crate::solve::knobs::Knob {
            name: $name,
            doc: $doc,
            kind: $crate::solve::knobs::KnobKind::Flag { off: $off, on: $on },
            get: |c| if c.$field { 1.0 } else { 0.0 },
            set: |c, v| c.$field = v != 0.0,
        }
    };
}
pub(crate) use knob;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn values_are_checked_by_kind() {
        assert!(check("steps", KnobKind::Count, 10.0).is_ok());
        let e = check("steps", KnobKind::Count, 2.5).unwrap_err();
        assert!(e.contains("whole number"), "{e}");
        assert!(check("lr", KnobKind::Real, f64::NAN).is_err());
        let flag = KnobKind::Flag {
            off: "off",
            on: "keep bone lengths",
        };
        assert!(check("skeleton", flag, 1.0).is_ok());
        let e = check("skeleton", flag, 2.0).unwrap_err();
        assert!(e.contains("keep bone lengths"), "{e}");
    }
}
