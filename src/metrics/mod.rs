//! Measurement (`metrics`): motion metrics, a learned text–motion evaluator, and the `mprog eval`
//! report comparing real test clips, a model and a trivial baseline.
//!
//! | part | module | what |
//! | --- | --- | --- |
//! | actions and paraphrases | [`actions`], [`paraphrases`] | named actions measured on generated motions (`bench actions`); the held-out paraphrase set, exact caption against other wordings (`bench paraphrases`) |
//! | per-motion metrics | [`per_motion`] | foot skating, max acceleration, bone-length variation, floor penetration, speed, turn, wrists above head |
//! | plausibility | [`plausibility`] | every output held against an envelope measured on real clips: snaps, speed, floor, skating, people overlapping, rigid parts, facing; located in time |
//! | linear algebra | [`linalg`] | Jacobi eigen-decomposition, PSD square root (f64) |
//! | set scores | [`scores`] | FID, diversity, R-precision on embeddings |
//! | evaluator | [`encoder`], [`evaluator`], [`train_encoder`], [`card`] | contrastive motion/caption encoders, their files, their training |
//! | text match | [`text_match`] | a motion's similarity to its prompts by the evaluator, per prompt span, long spans in windows |
//! | report | [`report`], [`table`] | generate for test captions, score every set, markdown tables |

pub mod actions;
pub mod card;
pub mod crouch;
pub mod encoder;
pub mod error;
pub mod evaluator;
pub mod linalg;
pub mod paraphrases;
pub mod per_motion;
pub mod plausibility;
pub mod report;
pub mod scores;
pub mod table;
pub mod text_match;
pub mod train_encoder;

pub use error::MetricsError;
pub use evaluator::{Evaluator, EvaluatorManifest, default_evaluator_dir};
pub use per_motion::MotionMetrics;
pub use report::{EvalReport, EvalSettings, run_eval};
pub use table::report_markdown;
pub use train_encoder::{EncoderTrainConfig, train_evaluator};

#[cfg(test)]
mod tests;
