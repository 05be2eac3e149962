//! Evaluation: motion metrics, a learned text–motion evaluator, and the `mprog eval`
//! report comparing real test clips, a model and a trivial baseline.
//!
//! | part | module | what |
//! | --- | --- | --- |
//! | per-motion metrics | [`metrics`] | foot skating, max acceleration, bone-length variation, floor penetration, speed, turn, wrists above head |
//! | linear algebra | [`linalg`] | Jacobi eigen-decomposition, PSD square root (f64) |
//! | set scores | [`scores`] | FID, diversity, R-precision on embeddings |
//! | evaluator | [`encoder`], [`evaluator`], [`train`], [`card`] | contrastive motion/caption encoders, their files, their training |
//! | report | [`report`], [`table`] | generate for test captions, score every set, markdown tables |

pub mod card;
pub mod encoder;
pub mod error;
pub mod evaluator;
pub mod linalg;
pub mod metrics;
pub mod report;
pub mod scores;
pub mod table;
pub mod train;

pub use error::EvalError;
pub use evaluator::{Evaluator, EvaluatorManifest, default_evaluator_dir};
pub use metrics::MotionMetrics;
pub use report::{EvalReport, EvalSettings, run_eval};
pub use table::report_markdown;
pub use train::{EncoderTrainConfig, train_evaluator};

#[cfg(test)]
mod tests;
