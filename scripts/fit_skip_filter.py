#!/usr/bin/env python3
"""How well would a linear temporal filter alone denoise x_t at small t?

Noises 300 training clips of a dataset built by `mprog data build` (normalised with its
own mean and std, cosine schedule) and fits, per feature, the least-squares 9-tap filter
x0[n] ~ sum_k w_k x_t[n + k - 4] (edges repeated). Prints its x0 MSE next to the
identity's, x_t / sqrt(alpha_bar). Compare with the model's x0 MSE from
`cargo run --release --example low_noise_probe`. Needs numpy only.

    python3 scripts/fit_skip_filter.py data/combined
"""
import json
import sys

import numpy as np

TAPS = 9


def alpha_bar(t, steps=1000):
    s = ((t / steps + 0.008) / 1.008) * np.pi / 2
    return np.cos(s) ** 2


def main(root):
    clips = json.load(open(f"{root}/clips.json"))["clips"]
    features = np.load(f"{root}/features.npy", mmap_mode="r")
    mean, std = np.load(f"{root}/mean.npy"), np.load(f"{root}/std.npy")
    rng = np.random.default_rng(0)
    train = [c for c in clips if c["split"] == "train" and c["frames"] >= 60]
    chosen = rng.choice(len(train), 300, replace=False)
    x0s = [
        (np.asarray(features[train[i]["offset"] : train[i]["offset"] + train[i]["frames"]]) - mean)
        / std
        for i in chosen
    ]
    half = TAPS // 2
    for t in [20, 40, 100, 200]:
        a = alpha_bar(t)
        inputs, targets = [], []
        for x0 in x0s:
            xt = np.sqrt(a) * x0 + np.sqrt(1 - a) * rng.standard_normal(x0.shape)
            padded = np.pad(xt, ((half, half), (0, 0)), mode="edge")
            inputs.append(np.stack([padded[k : k + len(x0)] for k in range(TAPS)], -1))
            targets.append(x0)
        inputs, targets = np.concatenate(inputs), np.concatenate(targets)
        identity = ((inputs[:, :, half] / np.sqrt(a) - targets) ** 2).mean()
        fitted = 0.0
        for f in range(inputs.shape[1]):
            w, *_ = np.linalg.lstsq(inputs[:, f, :], targets[:, f], rcond=None)
            fitted += ((inputs[:, f, :] @ w - targets[:, f]) ** 2).mean()
        print(f"t={t}: identity MSE {identity:.5f}, best {TAPS}-tap filter {fitted / inputs.shape[1]:.5f}")


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else "data/combined")
