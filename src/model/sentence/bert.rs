//! BERT encoder in burn (post-norm layers, erf GELU) with mean pooling over the tokens
//! and L2 normalisation, as sentence-transformers runs all-MiniLM-L6-v2.

use burn::nn::attention::{MhaInput, MultiHeadAttention, MultiHeadAttentionConfig};
use burn::nn::{
    Embedding, EmbeddingConfig, Initializer, LayerNorm, LayerNormConfig, Linear, LinearConfig,
};
use burn::prelude::*;
use burn::tensor::activation::gelu;
use serde::Deserialize;

/// The fields of the model's `config.json` (Hugging Face `BertConfig`) this encoder uses.
#[derive(Clone, Debug, Deserialize, PartialEq)]
pub struct BertConfig {
    /// Token ids.
    pub vocab_size: usize,
    /// Width of every token vector.
    pub hidden_size: usize,
    /// Encoder layers.
    pub num_hidden_layers: usize,
    /// Attention heads per layer.
    pub num_attention_heads: usize,
    /// Width of the feed-forward layer.
    pub intermediate_size: usize,
    /// Rows of the position table.
    pub max_position_embeddings: usize,
    /// Rows of the segment table.
    pub type_vocab_size: usize,
    /// LayerNorm epsilon (1e-12 for BERT).
    pub layer_norm_eps: f64,
    /// Must be "gelu" (the erf form).
    pub hidden_act: String,
}

impl BertConfig {
    /// Rejects configurations this encoder cannot run.
    pub fn check(&self) -> Result<(), String> {
        if self.hidden_act != "gelu" {
            return Err(format!(
                "hidden_act {:?}, only \"gelu\" is supported",
                self.hidden_act
            ));
        }
        let sizes = [self.vocab_size, self.hidden_size, self.num_hidden_layers]
            .into_iter()
            .chain([self.num_attention_heads, self.intermediate_size])
            .chain([self.max_position_embeddings, self.type_vocab_size]);
        if sizes.into_iter().any(|n| n == 0) {
            return Err("every size must be positive".into());
        }
        if !self.hidden_size.is_multiple_of(self.num_attention_heads) {
            return Err(format!(
                "hidden_size {} is not a multiple of num_attention_heads {}",
                self.hidden_size, self.num_attention_heads
            ));
        }
        Ok(())
    }
}

/// One post-norm transformer layer.
#[derive(Module, Debug)]
pub struct BertLayer {
    attention: MultiHeadAttention,
    attention_norm: LayerNorm,
    intermediate: Linear,
    output: Linear,
    output_norm: LayerNorm,
}

/// Embeddings and encoder layers; parameter names match `encoder.safetensors`.
#[derive(Module, Debug)]
pub struct Bert {
    word: Embedding,
    position: Embedding,
    token_type: Embedding,
    embed_norm: LayerNorm,
    layers: Vec<BertLayer>,
}

impl Bert {
    /// A zero-initialised encoder of shape `c` (weights are loaded over it).
    pub fn new(c: &BertConfig, device: &Device) -> Bert {
        let zeros = Initializer::Zeros;
        let emb = |n| {
            EmbeddingConfig::new(n, c.hidden_size)
                .with_initializer(zeros.clone())
                .init(device)
        };
        let norm = || {
            LayerNormConfig::new(c.hidden_size)
                .with_epsilon(c.layer_norm_eps)
                .init(device)
        };
        let linear = |i, o| {
            LinearConfig::new(i, o)
                .with_initializer(zeros.clone())
                .init(device)
        };
        let layer = || BertLayer {
            attention: MultiHeadAttentionConfig::new(c.hidden_size, c.num_attention_heads)
                .with_dropout(0.0)
                .with_initializer(zeros.clone())
                .init(device),
            attention_norm: norm(),
            intermediate: linear(c.hidden_size, c.intermediate_size),
            output: linear(c.intermediate_size, c.hidden_size),
            output_norm: norm(),
        };
        Bert {
            word: emb(c.vocab_size),
            position: emb(c.max_position_embeddings),
            token_type: emb(c.type_vocab_size),
            embed_norm: norm(),
            layers: (0..c.num_hidden_layers).map(|_| layer()).collect(),
        }
    }

    /// Width of the sentence vectors.
    pub fn dim(&self) -> usize {
        self.word.weight.dims()[1]
    }

    /// Rows of the position table (the longest sequence it can read).
    pub fn max_positions(&self) -> usize {
        self.position.weight.dims()[0]
    }

    /// Sentence vectors `[B, hidden]`, L2-normalised, for padded ids `[B, L]` and a mask
    /// `[B, L]` (1 for tokens, 0 for padding): the mean of [`Bert::hidden_states`] over
    /// the tokens.
    pub fn embed(&self, ids: Tensor<2, Int>, mask: Tensor<2>) -> Tensor<2> {
        let x = self.hidden_states(ids, mask.clone());
        let mask = mask.unsqueeze_dim::<3>(2);
        let counts = mask.clone().sum_dim(1).clamp_min(1.0);
        let pooled = (x * mask).sum_dim(1).div(counts).squeeze_dim::<2>(1);
        let norm = pooled.clone().square().sum_dim(1).sqrt().clamp_min(1e-12);
        pooled.div(norm)
    }

    /// The last layer's token states `[B, L, hidden]` for padded ids `[B, L]` and a mask
    /// `[B, L]` (rows of padding are not meaningful).
    pub fn hidden_states(&self, ids: Tensor<2, Int>, mask: Tensor<2>) -> Tensor<3> {
        let [_, len] = ids.dims();
        let position = self.position.weight.val().slice(0..len).unsqueeze_dim(0);
        let segment = self.token_type.weight.val().slice(0..1).unsqueeze_dim(0);
        let mut x = self
            .embed_norm
            .forward(self.word.forward(ids) + position + segment);
        let pad = mask.clone().equal_elem(0.0);
        for layer in &self.layers {
            let attn = MhaInput::self_attn(x.clone()).mask_pad(pad.clone());
            let context = layer.attention.forward(attn).context;
            x = layer.attention_norm.forward(x + context);
            let hidden = layer
                .output
                .forward(gelu(layer.intermediate.forward(x.clone())));
            x = layer.output_norm.forward(x + hidden);
        }
        x
    }
}
