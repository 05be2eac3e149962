//! Mirror averaging: a denoiser made exactly left/right symmetric at sampling time.
//!
//! The training data holds a mirrored copy of every clip with its caption's sides swapped,
//! so the best x̂0 for a mirrored input and caption is the mirror of the best x̂0 for the
//! original. A trained network only approximates that; its errors need not be symmetric
//! (measured: it does not lengthen turns, and one-seed left/right gaps are the shared
//! noise, see the model card's "Tried and not shipped"). Averaging the
//! prediction with the mirrored prediction of the mirrored question,
//!
//!   x̂0(x, c) = ½ [F(x, c) + M F(M x, M c)],
//!
//! projects it onto the symmetric predictors. M is an isometry of the normalised feature
//! space when the statistics are symmetric, so on mirror-symmetric data this averaged
//! prediction's x0 error is never above the network's own (Jensen's inequality). Both
//! halves run as one batch, so the cost is one denoiser call at twice the batch.

use super::denoiser::{Denoiser, DenoiserInput};
use super::prompt::{PromptEncoder, SIDE_WORDS, SentenceBatch, TextBatch};
use super::text::{TokenBatch, Vocabulary};
use crate::features::{FEATURE_DIM, FeatureMirror};
use burn::prelude::*;

/// A [`Denoiser`] averaged with its left/right mirror.
#[derive(Clone, Debug)]
pub struct MirrorAveraged<D> {
    inner: D,
    /// `[F]` feature each output feature reads from.
    source: Tensor<1, Int>,
    /// `[1, 1, F]` scale and shift of the mirror in normalised space.
    scale: Tensor<3>,
    shift: Tensor<3>,
    /// `[V]` token id → the id of the mirrored word (itself for most words).
    token_map: Tensor<1, Int>,
}

impl<D: Denoiser> MirrorAveraged<D> {
    /// Wraps `inner`, whose inputs are normalised with `mean` / `std` and whose text is
    /// read with `prompts`.
    pub fn new(
        inner: D,
        prompts: &PromptEncoder,
        mean: &[f32],
        std: &[f32],
        device: &Device,
    ) -> Self {
        let empty = Vocabulary::default();
        let vocab = match prompts {
            PromptEncoder::Words(vocab) => vocab,
            // Sentence batches carry their mirrored vectors; no ids to map.
            PromptEncoder::Sentences(_) => &empty,
        };
        let mirror = FeatureMirror::humanml3d();
        let (scale, shift) = mirror.normalized(mean, std);
        let source: Vec<i64> = mirror.source.iter().map(|&i| i as i64).collect();
        let mut ids: Vec<i64> = (0..vocab.len() as i64).collect();
        for (a, b) in SIDE_WORDS {
            if let (Some(&ia), Some(&ib)) = (vocab.words.get(a), vocab.words.get(b)) {
                ids.swap(ia, ib);
            }
        }
        let row = |v: Vec<f32>| Tensor::<1>::from_data(TensorData::new(v, [FEATURE_DIM]), device);
        MirrorAveraged {
            inner,
            source: Tensor::from_data(TensorData::new(source, [FEATURE_DIM]), device),
            scale: row(scale).reshape([1, 1, FEATURE_DIM]),
            shift: row(shift).reshape([1, 1, FEATURE_DIM]),
            token_map: Tensor::from_data(TensorData::new(ids, [vocab.len()]), device),
        }
    }

    /// `[B, N, F]` normalised features mirrored (an involution).
    pub fn mirror(&self, x: Tensor<3>) -> Tensor<3> {
        x.select(2, self.source.clone()) * self.scale.clone() + self.shift.clone()
    }

    /// `[B, L]` token ids with their side words swapped (mask and unknown words unchanged).
    fn mirror_ids(&self, tokens: &TokenBatch) -> Tensor<2, Int> {
        let [b, l] = tokens.ids.dims();
        let flat = tokens.ids.clone().reshape([b * l]);
        self.token_map.clone().select(0, flat).reshape([b, l])
    }
}

impl<D: Denoiser> Denoiser for MirrorAveraged<D> {
    fn predict_x0(&self, input: &DenoiserInput) -> Tensor<3> {
        let b = input.x_t.dims()[0];
        let both = DenoiserInput {
            x_t: Tensor::cat(vec![input.x_t.clone(), self.mirror(input.x_t.clone())], 0),
            timesteps: [input.timesteps.as_slice(), input.timesteps.as_slice()].concat(),
            text: match &input.text {
                TextBatch::Words(tokens) => TextBatch::Words(TokenBatch {
                    ids: Tensor::cat(vec![tokens.ids.clone(), self.mirror_ids(tokens)], 0),
                    mask: Tensor::cat(vec![tokens.mask.clone(); 2], 0),
                    unknown: [tokens.unknown.as_slice(); 2].concat(),
                }),
                TextBatch::Sentences(s) => TextBatch::Sentences(SentenceBatch {
                    vectors: Tensor::cat(vec![s.vectors.clone(), s.mirrored.clone()], 0),
                    mirrored: Tensor::cat(vec![s.mirrored.clone(), s.vectors.clone()], 0),
                    tokens: s
                        .tokens
                        .clone()
                        .map(|t| Box::new(t.clone().concat(t.swapped()))),
                }),
            },
            keep_text: Tensor::cat(vec![input.keep_text.clone(), input.keep_text.clone()], 0),
            padding: input
                .padding
                .as_ref()
                .map(|p| Tensor::cat(vec![p.clone(), p.clone()], 0)),
        };
        let out = self.inner.predict_x0(&both);
        let own = out.clone().narrow(0, 0, b);
        let back = self.mirror(out.narrow(0, b, b));
        (own + back) * 0.5
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::config::ModelConfig;
    use crate::model::denoiser::Mdm;
    use crate::model::noise::NoiseSource;

    fn vocab() -> Vocabulary {
        Vocabulary::from_captions(["a person walks and turns left", "someone turns right"], 8)
    }

    fn stats() -> (Vec<f32>, Vec<f32>) {
        // Deliberately not mirror-symmetric: the averaging must not rely on it.
        let mean = (0..FEATURE_DIM).map(|i| (i % 11) as f32 * 0.03).collect();
        let std = (0..FEATURE_DIM)
            .map(|i| 0.5 + (i % 3) as f32 * 0.25)
            .collect();
        (mean, std)
    }

    fn question(prompt: &str, x_t: Tensor<3>, dev: &Device) -> DenoiserInput {
        let b = x_t.dims()[0];
        DenoiserInput {
            x_t,
            timesteps: vec![300; b],
            text: TextBatch::Words(TokenBatch::new(&vocab(), &vec![prompt; b], dev)),
            keep_text: Tensor::ones([b], dev),
            padding: None,
        }
    }

    fn max_diff(a: Tensor<3>, b: Tensor<3>) -> f32 {
        (a - b).abs().max().into_scalar::<f32>()
    }

    /// Returns its input: already symmetric, so averaging must leave it alone.
    struct Identity;
    impl Denoiser for Identity {
        fn predict_x0(&self, input: &DenoiserInput) -> Tensor<3> {
            input.x_t.clone()
        }
    }

    #[test]
    fn a_symmetric_denoiser_is_unchanged() {
        let dev = Device::flex();
        let (mean, std) = stats();
        let avg = MirrorAveraged::new(Identity, &PromptEncoder::Words(vocab()), &mean, &std, &dev);
        let x = NoiseSource::new(1).tensor([2, 5, FEATURE_DIM], &dev);
        let out = avg.predict_x0(&question("someone turns left", x.clone(), &dev));
        assert!(max_diff(out, x.clone()) < 1e-5);
        assert!(max_diff(avg.mirror(avg.mirror(x.clone())), x) < 1e-5);
    }

    #[test]
    fn averaged_network_is_exactly_mirror_equivariant() {
        let dev = Device::flex();
        let cfg = ModelConfig {
            features: FEATURE_DIM,
            d_model: 32,
            layers: 2,
            heads: 2,
            d_ff: 64,
            dropout: 0.0,
            d_text: 8,
            text_encoder: Default::default(),
            max_frames: 40,
            input_skip: false,
            skip_taps: 1,
            skip_taps_below: None,
            side_input: false,
            text_control: None,
        };
        let net = Mdm::new(&cfg, vocab().len(), &dev).valid();
        let (mean, std) = stats();
        let x = NoiseSource::new(2).tensor([1, 6, FEATURE_DIM], &dev);
        // The bare network is not symmetric ...
        let plain = MirrorAveraged::new(
            net.clone(),
            &PromptEncoder::Words(vocab()),
            &mean,
            &std,
            &dev,
        );
        let left = net.predict_x0(&question("turns left", x.clone(), &dev));
        let right_of_mirror =
            net.predict_x0(&question("turns right", plain.mirror(x.clone()), &dev));
        assert!(max_diff(plain.mirror(left), right_of_mirror) > 1e-2);
        // ... the averaged one is: asking the mirrored question gives the mirrored answer.
        let left = plain.predict_x0(&question("turns left", x.clone(), &dev));
        let right_of_mirror = plain.predict_x0(&question("turns right", plain.mirror(x), &dev));
        assert!(max_diff(plain.mirror(left), right_of_mirror) < 1e-4);
    }

    #[test]
    fn side_words_swap_and_others_stay() {
        let dev = Device::flex();
        let v = vocab();
        let (mean, std) = stats();
        let avg = MirrorAveraged::new(
            Identity,
            &PromptEncoder::Words(v.clone()),
            &mean,
            &std,
            &dev,
        );
        let swapped = avg.mirror_ids(&TokenBatch::new(&v, &["someone turns left"], &dev));
        let expected = TokenBatch::new(&v, &["someone turns right"], &dev);
        assert_eq!(
            swapped.float().into_data().try_to_vec::<f32>().unwrap(),
            expected
                .ids
                .float()
                .into_data()
                .try_to_vec::<f32>()
                .unwrap()
        );
    }
}
