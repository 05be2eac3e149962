//! The `.mprog` language: syntax, checking, lowering to a differentiable error.
