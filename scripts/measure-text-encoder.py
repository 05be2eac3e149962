"""Full MiniLM vs model2vec-style static tables on the caption set: nearest-caption
agreement on paraphrases, class precision of the 10 nearest, caption R-precision, and
cosines of paraphrases vs unrelated prompts (the `nearest` threshold).

Usage: python scripts/measure-text-encoder.py <extracted wheel model dir> [cache dir]
"""

import os
import sys
import time

import numpy as np

sys.path.insert(0, os.path.dirname(__file__))
from minilm_ref import MiniLM  # noqa: E402
from text_encoder_captions import OUT_OF_DATA, PARAPHRASES, UNRELATED, captions  # noqa: E402


def token_table(m, cache):
    """model2vec's first step: every vocabulary id run alone as [CLS] id [SEP], mean-pooled."""
    path = os.path.join(cache, "minilm-token-table.npy")
    if os.path.exists(path):
        return np.load(path)
    vocab = m.w["embeddings.word_embeddings.weight"].shape[0]
    out = []
    for s in range(0, vocab, 1024):
        ids = np.array([[101, i, 102] for i in range(s, min(s + 1024, vocab))])
        h = m.hidden(ids, np.ones(ids.shape, np.float32))
        out.append(h.mean(1))
    t = np.concatenate(out).astype(np.float32)
    np.save(path, t)
    return t


def pca(t, dims):
    c = t - t.mean(0)
    _, _, vt = np.linalg.svd(c, full_matrices=False)
    return c @ vt[:dims].T


def static_encoder(m, table):
    def enc(sentences):
        rows = []
        for ids in m.token_ids(sentences):
            v = table[[i for i in ids if i not in (101, 102)]].mean(0)
            rows.append(v / max(np.linalg.norm(v), 1e-12))
        return np.stack(rows)

    return enc


def main():
    model_dir = sys.argv[1]
    cache = sys.argv[2] if len(sys.argv) > 2 else "/tmp"
    m = MiniLM(model_dir)
    t0 = time.time()
    raw = token_table(m, cache)
    print(f"token table {raw.shape} in {time.time() - t0:.0f} s")
    n = raw.shape[0]
    rank = np.arange(n)
    p = 1.0 / (rank + 2)
    p /= p.sum()
    reduced = pca(raw, 256)
    encoders = {
        "full MiniLM (burn, 45 MB f16)": m.encode,
        "static: raw token table, mean": static_encoder(m, raw),
        "static: PCA256 + Zipf log-rank (model2vec <=0.3)": static_encoder(m, reduced * np.log1p(rank)[:, None]),
        "static: PCA256 + SIF 1e-4 (model2vec >=0.4)": static_encoder(m, reduced * (1e-4 / (1e-4 + p))[:, None]),
    }
    caps = captions()
    texts = [c for c, _ in caps]
    classes = np.array([k for _, k in caps])
    print(f"{len(caps)} captions, {len(set(classes))} classes, {len(PARAPHRASES)} paraphrases")
    full_nearest = None
    rows = []
    for name, enc in encoders.items():
        ce = enc(texts)
        qe = enc([q for q, _ in PARAPHRASES])
        sims = qe @ ce.T
        nearest = sims.argmax(1)
        hit = np.mean([classes[j] in ok for j, (_, ok) in zip(nearest, PARAPHRASES)])
        top10 = np.mean([np.mean([classes[j] in ok for j in np.argsort(-s)[:10]]) for s, (_, ok) in zip(sims, PARAPHRASES)])
        if full_nearest is None:
            full_nearest = classes[nearest]
        agree = np.mean(classes[nearest] == full_nearest)
        cc = ce @ ce.T
        np.fill_diagonal(cc, -np.inf)
        rp = []
        for i in range(len(caps)):
            r = int((classes == classes[i]).sum()) - 1
            rp.append(np.mean(classes[np.argpartition(-cc[i], r)[:r]] == classes[i]))
        para_cos = sims.max(1)
        un = enc(UNRELATED) @ ce.T
        ood = enc(OUT_OF_DATA) @ ce.T
        rows.append((name, hit, agree, top10, np.mean(rp), para_cos, un.max(1), ood.max(1)))
        print(f"\n## {name}")
        for (q, ok), j, c in zip(PARAPHRASES, nearest, para_cos):
            mark = "ok " if classes[j] in ok else "MISS"
            print(f"  {mark} {q!r:48} -> {texts[j]!r} ({c:.2f})")
        for q, s in zip(UNRELATED + OUT_OF_DATA, np.concatenate([un, ood])):
            print(f"  far  {q!r:48} -> {texts[s.argmax()]!r} ({s.max():.2f})")
    print("\n| encoder | paraphrase nearest class right | agrees with full model | top-10 class precision | caption R-precision | paraphrase best cos min / median | unrelated best cos max | out-of-data best cos max |")
    print("|---|---|---|---|---|---|---|---|")
    for name, hit, agree, top10, rp, pc, un, ood in rows:
        print(f"| {name} | {hit:.2f} | {agree:.2f} | {top10:.2f} | {rp:.2f} | {pc.min():.2f} / {np.median(pc):.2f} | {un.max():.2f} | {ood.max():.2f} |")


if __name__ == "__main__":
    main()
