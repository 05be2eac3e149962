//! Model and training configuration (TOML files, stored next to weights).

use serde::{Deserialize, Serialize};

/// Shape of the denoiser.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ModelConfig {
    /// Feature width of a frame (263 for HumanML3D).
    #[serde(default = "default_features")]
    pub features: usize,
    /// Transformer width.
    pub d_model: usize,
    /// Encoder layers.
    pub layers: usize,
    /// Attention heads.
    pub heads: usize,
    /// Feed-forward width.
    pub d_ff: usize,
    /// Dropout in training.
    #[serde(default = "default_dropout")]
    pub dropout: f64,
    /// Width of the text vector fed to the condition token: the word embeddings of the
    /// bag-of-words encoder, or the sentence encoder's output (384 for MiniLM).
    pub d_text: usize,
    /// Which text encoder reads the prompts. Bundles without the field are bag-of-words.
    #[serde(default, skip_serializing_if = "TextEncoderKind::is_bag_of_words")]
    pub text_encoder: TextEncoderKind,
    /// Longest motion the model is asked for (frames).
    pub max_frames: usize,
    /// Add a learned, timestep-gated copy of the input to the output (`x̂0 = F(x_t) +
    /// g(t) ⊙ x_t`, g zero at initialisation): at small t the sample is nearly its own
    /// answer, and a network squeezing 263 features through its width copies the small
    /// columns (the root's yaw rate) badly. Bundles without it load as before.
    #[serde(default, skip_serializing_if = "is_false")]
    pub input_skip: bool,
    /// Frames the input skip reads around each frame (odd; 1 = the frame alone). With more,
    /// the skip is a timestep-gated temporal filter, `Σ_k g_k(t) ⊙ x_t[n + k − K/2]` (edges
    /// repeat the first and last valid frame): the attention layers copy a frame's own
    /// noise badly, and a 9-tap linear filter alone beats the trained transformer's x̂0
    /// at t ≤ 200 (book, model chapter, "Jitter and stretched bones"). Bundles without the
    /// field have 1.
    #[serde(default = "one_tap", skip_serializing_if = "is_one_tap")]
    pub skip_taps: usize,
    /// Timestep from which only the centre skip tap reads (None: all taps at every t).
    /// At high t the outer taps pass smoothed noise into x̂0, a slow wobble of the bone
    /// lengths that the attention layers must then cancel; below this the neighbours are
    /// nearly clean and the filter is what beats the transformer.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub skip_taps_below: Option<usize>,
    /// Add the prompt's side vector, its sentence vector minus that of the prompt with
    /// left and right swapped, through its own zero-initialised linear layer into the
    /// condition token (sentence encoders only). "kicks the left leg forward" and "… the
    /// right leg …" have cosine 0.986, so the side is a small part of either vector; the
    /// difference is all side, zero for a prompt that names none, and flips sign exactly
    /// under mirroring. Bundles without the field have none.
    #[serde(default, skip_serializing_if = "is_false")]
    pub side_input: bool,
    /// OMG's text ControlNet (`model::moc`, sentence encoders only): the text enters only
    /// through trainable layer copies and Mixture-of-Controllers blocks reading the
    /// prompt's token states, over a prior trained without text. A run with it trains
    /// only the ControlNet. Bundles without the field have none.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub text_control: Option<crate::model::moc::MocConfig>,
}

/// The text encoder of a denoiser.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub enum TextEncoderKind {
    /// Mean of word embeddings learned with the denoiser over the training vocabulary.
    #[default]
    #[serde(rename = "bag-of-words")]
    BagOfWords,
    /// The frozen pretrained sentence encoder (all-MiniLM-L6-v2, `models/text-encoder`):
    /// open vocabulary, one 384-d unit vector per prompt.
    #[serde(rename = "minilm")]
    Sentence,
}

impl TextEncoderKind {
    fn is_bag_of_words(&self) -> bool {
        *self == TextEncoderKind::BagOfWords
    }
}

fn is_false(b: &bool) -> bool {
    !*b
}

fn one_tap() -> usize {
    1
}

fn is_one_tap(v: &usize) -> bool {
    *v == 1
}

fn default_features() -> usize {
    263
}
fn default_dropout() -> f64 {
    0.1
}

impl Default for ModelConfig {
    fn default() -> Self {
        ModelConfig {
            features: 263,
            d_model: 256,
            layers: 4,
            heads: 4,
            d_ff: 1024,
            dropout: 0.1,
            d_text: 128,
            text_encoder: TextEncoderKind::BagOfWords,
            max_frames: 196,
            input_skip: false,
            skip_taps: 1,
            skip_taps_below: None,
            side_input: false,
            text_control: None,
        }
    }
}

/// Settings of a training run.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TrainConfig {
    /// Denoiser shape.
    pub model: ModelConfig,
    /// Clips per batch.
    pub batch_size: usize,
    /// Frames per training crop (clips shorter are padded and masked).
    pub crop_frames: usize,
    /// Peak learning rate (AdamW).
    pub learning_rate: f64,
    /// Linear warm-up steps.
    pub warmup_steps: usize,
    /// AdamW weight decay.
    pub weight_decay: f64,
    /// Gradient norm clip.
    pub grad_clip: f64,
    /// Probability of dropping the text condition (classifier-free guidance).
    pub cond_drop: f64,
    /// EMA decay of the shipped weights.
    pub ema_decay: f64,
    /// Total optimisation steps (training can stop and resume before it).
    pub steps: usize,
    /// Save a checkpoint every this many steps.
    pub checkpoint_every: usize,
    /// Weight of the foot-contact velocity loss on recovered joints (0 disables).
    #[serde(default)]
    pub foot_loss: f64,
    /// Weight of the velocity loss on the stored joint positions (0 disables).
    #[serde(default)]
    pub velocity_loss: f64,
    /// Weight of the bone-length loss on the predicted pose, in cm² per bone (0 disables).
    #[serde(default, skip_serializing_if = "is_zero")]
    pub bone_loss: f64,
    /// Weigh each clip's bone-length term by its signal fraction ᾱ_t: at large t x̂0 is the
    /// mean of many poses, whose bones are rightly shorter, and only near the end of the
    /// chain must the pose be one body.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub bone_loss_by_signal: bool,
    /// Weight of an extra x0 MSE on the 4 root columns (yaw velocity, XZ velocity,
    /// height), averaged over those columns alone: the base MSE gives each of them 1/263
    /// of the loss, and a turn is the integral of the yaw velocity over the clip, so a
    /// small per-frame bias halves it (0 disables).
    #[serde(default)]
    pub root_loss: f64,
    /// Probability of dropping each word of a training caption (at least one content word
    /// stays): captions always say "walks forward" or "walks straight ahead", so without it
    /// "a person walks" was a word set the bag-of-words encoder never saw, and stood still.
    #[serde(default)]
    pub word_drop: f64,
    /// Sampling weight of clips by source folder: a clip whose `source` path starts with a
    /// key is drawn that many times as often as one with weight 1 (the longest matching key
    /// wins; clips matching none weigh 1). A few minutes of jumps and kicks next to hours of
    /// walking are otherwise seen too rarely to be learned.
    #[serde(default, skip_serializing_if = "std::collections::BTreeMap::is_empty")]
    pub source_weights: std::collections::BTreeMap<String, f64>,
    /// Average the x0 MSE per clip, then over the batch (MDM's `masked_l2`), instead of
    /// over every valid frame of the batch: with frame weighting a 13-frame hop padded to a
    /// 120-frame batch counts a ninth of a walk, whatever `source_weights` says.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub loss_per_clip: bool,
    /// Fraction of samples whose timestep is drawn from the last tenth of the chain
    /// (`t ≥ 900`) instead of uniformly. With the cosine schedule a clip is still readable
    /// from x_t up to t ≈ 950 (`examples/caption_probe.rs`): the caption decides a jump or a
    /// kick only in the last few percent of the chain, which uniform draws visit 5 % of the
    /// time.
    #[serde(default, skip_serializing_if = "is_zero")]
    pub high_noise_fraction: f64,
    /// Timestep t₀ under which each clip's x0 MSE is weighed up by `(1−ᾱ_t₀)/(1−ᾱ_t)`, at
    /// most [`Self::low_noise_loss_cap`]: the x0 MSE of a small t is the square of a small
    /// noise, so unweighted the last steps of the chain, where a sample's jitter is taken
    /// out, hardly count (0: off).
    #[serde(default, skip_serializing_if = "is_zero_usize")]
    pub low_noise_below: usize,
    /// Largest weight of [`Self::low_noise_below`].
    #[serde(default, skip_serializing_if = "is_zero")]
    pub low_noise_loss_cap: f64,
    /// Probability of training a sample on a rule-made paraphrase of its caption instead
    /// of the caption (sentence-encoder runs; `train::augment`): a paraphrase the model
    /// never saw drifted away from what its caption does.
    #[serde(default, skip_serializing_if = "is_zero")]
    pub paraphrase_prob: f64,
    /// Least cosine between a paraphrase and its caption for the paraphrase to be kept.
    #[serde(
        default = "default_paraphrase_min_cos",
        skip_serializing_if = "is_default_min_cos"
    )]
    pub paraphrase_min_cos: f64,
    /// Most paraphrases kept per caption.
    #[serde(
        default = "default_paraphrases_per_caption",
        skip_serializing_if = "is_default_per_caption"
    )]
    pub paraphrases_per_caption: usize,
    /// A TOML file whose strings are wordings never trained on (the held-out paraphrase
    /// set the run is measured on).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub paraphrase_holdout: Option<String>,
    /// Gaussian noise per dimension added to each sentence vector (then renormalised), so
    /// the model answers a neighbourhood of each caption, not its point.
    #[serde(default, skip_serializing_if = "is_zero")]
    pub text_noise: f64,
    /// Probability that a clip shorter than `crop_frames` is placed inside a longer
    /// window (up to twice its length) with its first pose held before it and its last
    /// after: an action learnt only at its clip's length did not happen in a longer motion.
    #[serde(default, skip_serializing_if = "is_zero")]
    pub hold_pad: f64,
    /// Probability that a sample's sentence vector is replaced by the empty one for the
    /// text ControlNet's AdaIN (OMG drops its `<eos>` token half the time, so the
    /// per-token experts learn to carry the text alone).
    #[serde(default, skip_serializing_if = "is_zero")]
    pub eos_drop: f64,
    /// Seed of the data order and noise.
    pub seed: u64,
    /// Consistency distillation of a teacher bundle into a few-step model, instead of
    /// the x0 loss (`model::train::distil`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub distil: Option<DistilConfig>,
}

/// Settings of a consistency-distillation run (MotionLCM §3.3, after LCM): the student
/// learns to map any point of the teacher's guided DDIM trajectory to its end.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DistilConfig {
    /// The teacher's model bundle (its denoiser config must be the run's).
    pub teacher: String,
    /// The teacher's classifier-free guidance scale, baked into the student (which then
    /// samples at scale 1).
    pub guidance: f64,
    /// Steps of the teacher's DDIM grid: each target is one teacher step of
    /// 1000 / `grid` timesteps (the skipping step).
    pub grid: usize,
    /// Pseudo-Huber constant of the loss, in normalised feature units.
    pub huber_c: f64,
}

impl DistilConfig {
    /// Checks the numbers; the message names the field.
    pub fn check(&self) -> Result<(), String> {
        in_range("distil.grid", self.grid, 2, 1000)?;
        if !(self.guidance.is_finite() && (1.0..=20.0).contains(&self.guidance)) {
            return Err(format!(
                "`distil.guidance` is {}; it must be in [1, 20]",
                self.guidance
            ));
        }
        if !(self.huber_c.is_finite() && self.huber_c > 0.0 && self.huber_c <= 1.0) {
            return Err(format!(
                "`distil.huber_c` is {}; it must be in (0, 1]",
                self.huber_c
            ));
        }
        Ok(())
    }
}

fn default_paraphrase_min_cos() -> f64 {
    0.8
}

fn default_paraphrases_per_caption() -> usize {
    16
}

fn is_default_min_cos(v: &f64) -> bool {
    *v == default_paraphrase_min_cos()
}

fn is_default_per_caption(v: &usize) -> bool {
    *v == default_paraphrases_per_caption()
}

impl Default for TrainConfig {
    fn default() -> Self {
        TrainConfig {
            model: ModelConfig::default(),
            batch_size: 32,
            crop_frames: 120,
            learning_rate: 2e-4,
            warmup_steps: 300,
            weight_decay: 0.0,
            grad_clip: 1.0,
            cond_drop: 0.1,
            ema_decay: 0.999,
            steps: 100_000,
            checkpoint_every: 200,
            foot_loss: 0.0,
            velocity_loss: 0.0,
            bone_loss: 0.0,
            bone_loss_by_signal: false,
            root_loss: 0.0,
            word_drop: 0.0,
            source_weights: Default::default(),
            loss_per_clip: false,
            high_noise_fraction: 0.0,
            low_noise_below: 0,
            low_noise_loss_cap: 0.0,
            paraphrase_prob: 0.0,
            paraphrase_min_cos: default_paraphrase_min_cos(),
            paraphrases_per_caption: default_paraphrases_per_caption(),
            paraphrase_holdout: None,
            text_noise: 0.0,
            hold_pad: 0.0,
            eos_drop: 0.0,
            seed: 1,
            distil: None,
        }
    }
}

fn is_zero_usize(v: &usize) -> bool {
    *v == 0
}

fn is_zero(v: &f64) -> bool {
    *v == 0.0
}

/// Largest accepted layer width, head count, layer count, … of a configuration: far above
/// anything that trains on a CPU, low enough that a typo cannot ask for terabytes.
const MAX_SIZE: usize = 1 << 16;

/// Most frames the input skip may read around a frame.
const MAX_SKIP_TAPS: usize = 31;

fn in_range(name: &str, value: usize, lo: usize, hi: usize) -> Result<(), String> {
    if (lo..=hi).contains(&value) {
        Ok(())
    } else {
        Err(format!("`{name}` is {value}; it must be in {lo}..={hi}"))
    }
}

fn fraction(name: &str, value: f64, hi_open: bool) -> Result<(), String> {
    let ok = value.is_finite() && value >= 0.0 && if hi_open { value < 1.0 } else { value <= 1.0 };
    if ok {
        Ok(())
    } else {
        let hi = if hi_open { "1)" } else { "1]" };
        Err(format!("`{name}` is {value}; it must be in [0, {hi}"))
    }
}

impl ModelConfig {
    /// Checks that the shape can be built; the message names the field.
    pub fn check(&self) -> Result<(), String> {
        in_range("features", self.features, 263, 263)?;
        in_range("d_model", self.d_model, 1, MAX_SIZE)?;
        in_range("layers", self.layers, 1, 256)?;
        in_range("heads", self.heads, 1, self.d_model)?;
        if !self.d_model.is_multiple_of(self.heads) {
            return Err(format!(
                "`d_model` ({}) must be a multiple of `heads` ({})",
                self.d_model, self.heads
            ));
        }
        in_range("d_ff", self.d_ff, 1, MAX_SIZE)?;
        in_range("d_text", self.d_text, 1, MAX_SIZE)?;
        in_range("max_frames", self.max_frames, 2, MAX_SIZE)?;
        in_range("skip_taps", self.skip_taps, 1, MAX_SKIP_TAPS)?;
        if self.skip_taps.is_multiple_of(2) {
            return Err(format!("`skip_taps` ({}) must be odd", self.skip_taps));
        }
        if self.side_input && self.text_encoder != TextEncoderKind::Sentence {
            return Err("`side_input` needs `text_encoder = \"minilm\"`".into());
        }
        if let Some(c) = &self.text_control {
            c.check()?;
            if self.text_encoder != TextEncoderKind::Sentence {
                return Err("`text_control` needs `text_encoder = \"minilm\"`".into());
            }
        }
        if self.skip_taps > 1 && !self.input_skip {
            return Err("`skip_taps` above 1 needs `input_skip = true`".into());
        }
        if let Some(below) = self.skip_taps_below {
            in_range("skip_taps_below", below, 1, MAX_SIZE)?;
            if self.skip_taps == 1 {
                return Err("`skip_taps_below` needs `skip_taps` above 1".into());
            }
        }
        fraction("dropout", self.dropout, true)
    }
}

impl TrainConfig {
    /// Checks the settings (and the model shape); the message names the field.
    pub fn check(&self) -> Result<(), String> {
        self.model.check().map_err(|e| format!("[model] {e}"))?;
        if let Some(d) = &self.distil {
            d.check().map_err(|e| format!("[distil] {e}"))?;
        }
        in_range("batch_size", self.batch_size, 1, MAX_SIZE)?;
        in_range("crop_frames", self.crop_frames, 2, MAX_SIZE)?;
        in_range("checkpoint_every", self.checkpoint_every, 1, usize::MAX)?;
        for (name, v) in [
            ("learning_rate", self.learning_rate),
            ("grad_clip", self.grad_clip),
        ] {
            if !(v.is_finite() && v > 0.0) {
                return Err(format!("`{name}` is {v}; it must be a positive number"));
            }
        }
        for (name, v) in [
            ("weight_decay", self.weight_decay),
            ("foot_loss", self.foot_loss),
            ("velocity_loss", self.velocity_loss),
            ("bone_loss", self.bone_loss),
            ("root_loss", self.root_loss),
            ("low_noise_loss_cap", self.low_noise_loss_cap),
        ] {
            if !(v.is_finite() && v >= 0.0) {
                return Err(format!("`{name}` is {v}; it must be zero or positive"));
            }
        }
        for (prefix, w) in &self.source_weights {
            if !(w.is_finite() && *w > 0.0 && *w <= 1e6) {
                return Err(format!(
                    "`source_weights` of \"{prefix}\" is {w}; it must be a positive number"
                ));
            }
        }
        fraction("cond_drop", self.cond_drop, false)?;
        fraction("word_drop", self.word_drop, false)?;
        fraction("high_noise_fraction", self.high_noise_fraction, false)?;
        fraction("paraphrase_prob", self.paraphrase_prob, false)?;
        fraction("paraphrase_min_cos", self.paraphrase_min_cos, false)?;
        fraction("hold_pad", self.hold_pad, false)?;
        fraction("eos_drop", self.eos_drop, false)?;
        if self.eos_drop > 0.0 && self.model.text_control.is_none() {
            return Err("`eos_drop` needs a `[model.text_control]`".into());
        }
        if self.model.text_control.is_some() && self.distil.is_some() {
            return Err("a run trains a text ControlNet or distils, not both".into());
        }
        in_range(
            "paraphrases_per_caption",
            self.paraphrases_per_caption,
            1,
            1000,
        )?;
        if !(self.text_noise.is_finite() && (0.0..=1.0).contains(&self.text_noise)) {
            return Err(format!(
                "`text_noise` is {}; it must be in [0, 1]",
                self.text_noise
            ));
        }
        if (self.paraphrase_prob > 0.0 || self.text_noise > 0.0)
            && self.model.text_encoder != TextEncoderKind::Sentence
        {
            return Err(
                "`paraphrase_prob` and `text_noise` need `text_encoder = \"minilm\"`".into(),
            );
        }
        in_range(
            "low_noise_below",
            self.low_noise_below,
            0,
            crate::model::schedule::DIFFUSION_STEPS - 1,
        )?;
        if self.low_noise_below > 0 && self.low_noise_loss_cap < 1.0 {
            return Err(format!(
                "`low_noise_loss_cap` is {}; with `low_noise_below` it must be at least 1",
                self.low_noise_loss_cap
            ));
        }
        fraction("ema_decay", self.ema_decay, true)
    }
}
