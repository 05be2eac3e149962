//! The model card written next to the evaluator weights (`README.md`).

use super::evaluator::EvaluatorManifest;

/// Markdown card describing an evaluator: what it is, how it was trained, how well it
/// separates real validation clips, and what its numbers mean.
pub fn model_card(m: &EvaluatorManifest) -> String {
    let c = &m.config;
    let val = match m.val_r_precision {
        Some([a, b, d]) => format!("top-1 {a:.3}, top-2 {b:.3}, top-3 {d:.3}"),
        None => "not measured (too few validation clips)".into(),
    };
    format!(
        "# mprog evaluator (version {version})\n\n\
         A small text–motion embedding used by `mprog eval` for FID, diversity and\n\
         R-precision. It plays the role of the T2M evaluator of Guo et al. for this project's\n\
         data (Bandai Namco mocap, label-derived captions); its numbers are comparable only\n\
         with other numbers from the same weights.\n\n\
         | | |\n| --- | --- |\n\
         | motion encoder | Linear({f}→{h}), Conv1d k{k} ({h}→{h}), Conv1d k{k} ({h}→{h2}), GELU, masked mean + max pooling, Linear({h4}→{d}), unit length |\n\
         | caption encoder | mean of {w}-d word embeddings ({vocab} ids), Linear({w}→{d}), GELU, Linear({d}→{d}), unit length |\n\
         | input | HumanML3D features normalised with this folder's mean.npy/std.npy (train split), first {max} frames |\n\
         | training | symmetric InfoNCE, τ = {tau}, positives = same content and style label, {steps} steps on {clips} train clips, {secs:.0} s CPU |\n\
         | final training loss | {loss:.3} |\n\
         | validation R-precision (32 captions, 31 of other labels) | {val} |\n\
         | weights | model.safetensors, {prec} |\n\n\
         Embeddings are unit vectors: diversity lies in [0, 2] and FID in [0, 6]; \
         real test clips score a small positive FID against other test clips because of the\n\
         sample size.\n\n\
         Retrain with `mprog eval train-encoder --data <dataset> --out models/evaluator`.\n",
        version = m.version,
        f = c.features,
        h = c.hidden,
        h2 = 2 * c.hidden,
        h4 = 4 * c.hidden,
        k = c.kernel,
        d = c.embed_dim,
        w = c.word_dim,
        vocab = m.vocab_size,
        max = c.max_frames,
        tau = c.temperature,
        steps = m.steps,
        clips = m.train_clips,
        secs = m.train_seconds,
        loss = m.final_loss,
        prec = if m.half_precision { "f16" } else { "f32" },
    )
}
