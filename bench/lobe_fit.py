#!/usr/bin/env python3
"""How much a first-bounce mixture with more Gaussian lobes could lower the first bounce's
variance (issue 9's lever 6), fitted offline to real VPLs instead of learnt online, for
Lambert-only scenes (docs/guiding.md, "How many lobes").

    build/bench/vpl_dump scenes/cornell-box.json 120x68 64 /tmp/cb.bin 1
    python3 bench/lobe_fit.py /tmp/cb.bin --pixels 400

Per pixel p (a random sample of surface pixels at least --apron from the border): the VPLs of
its (2 apron + 1)^2 neighbourhood, re-expressed at p as the train kernel does (direction to the
VPL's point y, density r = p_A d^2 / cos_y, weight a = lum(f cos L) / r with f = albedo / pi),
frames [0, --fit-frames) to fit, the rest to evaluate. Each model D = sum_j pi_j N_j(M^-1(w)) /
(2 pi) + (1 - sum pi_j) cos / pi (the paper's mixture, kernels/shared/pmm.h, with K lobes in
the concentric square of p's frame) is fitted by weighted batch EM to convergence (the best that
online EM with these samples could do), and the one-sample estimator's second moment
M2 = E_r[F^2 / (D r)] estimated on the held-out samples; the variance M2 - I^2 includes the
noise of each VPL's one-path radiance, as the image's does. Printed: the mean over pixels of
the variance relative to (I^2 + 0.01) per model, and its ratio to BSDF sampling's.
"""
import argparse
import math

import numpy as np

SKY, EMITTER = 1, 2


def load(path):
    raw = np.fromfile(path, dtype=np.uint32, count=4)
    if raw[0] != 0x4C505452 or raw[1] != 0x314C5056:
        raise SystemExit(f"lobe_fit.py: {path} is not a vpl_dump file")
    w, h = int(raw[2]), int(raw[3])
    data = np.fromfile(path, dtype=np.float32, offset=16)
    if data.size % (w * h * 28):
        raise SystemExit(f"lobe_fit.py: {path} is truncated")
    return data.reshape(-1, h, w, 28)


def hemisphere_to_square(w):
    """M^-1 of kernels/shared/mapping.h (the concentric map with the equal-area lift; numpy's
    arctan where the kernel has its polynomial)."""
    x, y, z = w[:, 0], w[:, 1], w[:, 2]
    r = np.sqrt(np.clip(1.0 - z, 0.0, 1.0))
    u = np.full((len(w), 2), 0.5)
    with np.errstate(divide="ignore", invalid="ignore"):
        xa = np.abs(x) >= np.abs(y)
        a = np.where(xa, np.where(x > 0, r, -r), 0.0)
        b = np.where(xa, a * np.arctan(y / x) * 4 / math.pi, np.where(y > 0, r, -r))
        a = np.where(xa, a, b * np.arctan(x / y) * 4 / math.pi)
    ok = (r > 0) & ~((x == 0) & (y == 0))
    u[ok, 0] = np.clip(0.5 * (a[ok] + 1), 0, 1)
    u[ok, 1] = np.clip(0.5 * (b[ok] + 1), 0, 1)
    return u


def frame(n):
    """An orthonormal basis around n (Frisvad's, as any fixed one serves an offline fit)."""
    if n[2] < -0.9999999:
        return np.array([0.0, -1.0, 0.0]), np.array([-1.0, 0.0, 0.0])
    a = 1.0 / (1.0 + n[2])
    b = -n[0] * n[1] * a
    return np.array([1.0 - n[0] ** 2 * a, b, -n[0]]), np.array([b, 1.0 - n[1] ** 2 * a, -n[1]])


def lum(c):
    return 0.2126 * c[..., 0] + 0.7152 * c[..., 1] + 0.0722 * c[..., 2]


def samples_at(d, frames, py, px, apron):
    """The neighbourhood's VPLs of `frames` at pixel (py, px): square coordinates u, cosine,
    density r and F = lum(f cos L) of each."""
    out_u, out_cos, out_r, out_f = [], [], [], []
    for f in frames:
        g = d[f, py, px]
        x0, n, albedo = g[0:3], g[4:7], g[8:11]
        t, b = frame(n)
        nb = d[f, py - apron:py + apron + 1, px - apron:px + apron + 1].reshape(-1, 28)
        info = nb[:, 27].astype(np.uint32)
        valid = (info & 1) != 0
        distant = (info & 2) != 0
        nb, distant = nb[valid], distant[valid]
        to = nb[:, 16:19] - x0
        d2 = np.einsum("ij,ij->i", to, to)
        with np.errstate(divide="ignore", invalid="ignore"):
            w = np.where(distant[:, None], nb[:, 16:19], to / np.sqrt(d2)[:, None])
            cos_y = np.abs(np.einsum("ij,ij->i", nb[:, 20:23], w))
            r = np.where(distant, nb[:, 19], nb[:, 19] * d2 / cos_y)
        cos_p = w @ n
        keep = (cos_p > 1e-4) & np.isfinite(r) & (r > 0)
        w, r, cos_p, radiance = w[keep], r[keep], cos_p[keep], nb[keep, 24:27]
        local = np.stack([w @ t, w @ b, cos_p], axis=1)
        out_u.append(hemisphere_to_square(local))
        out_cos.append(cos_p)
        out_r.append(r)
        out_f.append(lum(albedo / math.pi * radiance) * cos_p)
    return (np.concatenate(out_u), np.concatenate(out_cos), np.concatenate(out_r), np.concatenate(out_f))


def gauss(u, mean, cov):
    det = cov[0, 0] * cov[1, 1] - cov[0, 1] ** 2
    inv = np.array([[cov[1, 1], -cov[0, 1]], [-cov[0, 1], cov[0, 0]]]) / det
    d = u - mean
    q = np.einsum("ij,jk,ik->i", d, inv, d)
    return np.exp(-0.5 * q) / (2 * math.pi * math.sqrt(det))


def density(model, u, cos):
    pis, means, covs = model
    dens = (1.0 - sum(pis)) * cos / math.pi
    for p, m, c in zip(pis, means, covs):
        dens = dens + p * gauss(u, m, c) / (2 * math.pi)
    return dens


def fit(u, cos, a, k, pi_cap, rng, iterations=80, second_moment=False):
    """Weighted EM of K lobes beside the fixed BSDF component, from a weighted k-means++ start.
    With second_moment the target is F^2 / D of the current model instead of F (each iteration
    reweights a sample of weight a = F / r by a / D): the fixed point lowers the estimator's
    second moment, integral F^2 / D, where the plain fit maximises the likelihood of F (lever 2
    of issue 9, "fit for variance")."""
    base = a
    total = a.sum()
    if k == 0 or total <= 0:
        return ([], [], [])
    p = a / total
    means = [u[rng.choice(len(u), p=p)]]
    for _ in range(1, k):
        dist = np.min([np.sum((u - m) ** 2, axis=1) for m in means], axis=0)
        q = p * dist
        means.append(u[rng.choice(len(u), p=q / q.sum())] if q.sum() > 0 else u[rng.choice(len(u), p=p)])
    pis = [min(pi_cap, 0.5) / k] * k
    covs = [np.eye(2) * 0.02 for _ in range(k)]
    for _ in range(iterations):
        model = (pis, means, covs)
        dens = density(model, u, cos)
        if second_moment:
            a = base * base / np.maximum(dens, 1e-12)
            total = a.sum()
        new_pis, new_means, new_covs = [], [], []
        for j in range(k):
            resp = a * pis[j] * gauss(u, means[j], covs[j]) / (2 * math.pi) / dens
            s0 = resp.sum()
            if s0 <= 1e-12 * total:
                new_pis.append(0.0)
                new_means.append(means[j])
                new_covs.append(covs[j])
                continue
            m = (resp[:, None] * u).sum(0) / s0
            d = u - m
            c = (resp[:, None, None] * np.einsum("ij,ik->ijk", d, d)).sum(0) / s0 + np.eye(2) * 1e-4
            new_pis.append(s0 / total)
            new_means.append(m)
            new_covs.append(c)
        s = sum(new_pis)
        if s > pi_cap:
            new_pis = [x * pi_cap / s for x in new_pis]
        pis, means, covs = new_pis, new_means, new_covs
    return (pis, means, covs)


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("dump", help="a file written by build/bench/vpl_dump")
    parser.add_argument("--pixels", type=int, default=400)
    parser.add_argument("--apron", type=int, default=2)
    parser.add_argument("--fit-frames", type=int, default=48)
    parser.add_argument("--seed", type=int, default=1)
    args = parser.parse_args()
    d = load(args.dump)
    frames, h, w, _ = d.shape
    if not 0 < args.fit_frames < frames:
        raise SystemExit(f"lobe_fit.py: --fit-frames must be in (0, {frames})")
    rng = np.random.default_rng(args.seed)
    flags = d[0, :, :, 12].astype(np.uint32)
    a = args.apron
    ys, xs = np.nonzero((flags & (SKY | EMITTER)) == 0)
    inside = (ys >= a) & (ys < h - a) & (xs >= a) & (xs < w - a)
    ys, xs = ys[inside], xs[inside]
    pick = rng.choice(len(ys), size=min(args.pixels, len(ys)), replace=False)
    models = {"BSDF": (0, 0.0, False), "1 lobe, pi <= 0.5": (1, 0.5, False), "1 lobe, pi <= 0.95": (1, 0.95, False),
              "2 lobes, pi <= 0.95": (2, 0.95, False), "3 lobes, pi <= 0.95": (3, 0.95, False),
              "4 lobes, pi <= 0.95": (4, 0.95, False), "1 lobe, pi <= 0.5, second moment": (1, 0.5, True),
              "1 lobe, pi <= 0.95, second moment": (1, 0.95, True),
              "2 lobes, pi <= 0.95, second moment": (2, 0.95, True)}
    rel = {name: [] for name in models}
    share = {name: [] for name in models}
    fit_frames, eval_frames = range(args.fit_frames), range(args.fit_frames, frames)
    for n, i in enumerate(pick):
        y, x = int(ys[i]), int(xs[i])
        u, cos, r, f = samples_at(d, fit_frames, y, x, a)
        eu, ecos, er, ef = samples_at(d, eval_frames, y, x, a)
        if len(u) < 50 or len(eu) < 20:
            continue
        weights = f / r
        estimate = (ef / er).mean()
        for name, (k, cap, second_moment) in models.items():
            model = fit(u, cos, weights, k, cap, rng, second_moment=second_moment)
            dens = density(model, eu, ecos)
            m2 = (ef ** 2 / (dens * er)).mean()
            rel[name].append((m2 - estimate ** 2) / (estimate ** 2 + 0.01))
            share[name].append(sum(model[0]))
        if (n + 1) % 100 == 0:
            print(f"{n + 1} pixels", flush=True)
    base = np.mean(rel["BSDF"])
    one = np.array(rel["1 lobe, pi <= 0.5"])
    print(f"{len(rel['BSDF'])} pixels, {args.fit_frames} frames to fit, {frames - args.fit_frames} to evaluate")
    print("| model | relative variance | / BSDF | - one lobe (pi <= 0.5), / BSDF, paired | mean sum of pi |")
    print("|---|---|---|---|---|")
    for name in models:
        v = np.array(rel[name])
        diff = (v - one) / base
        se = diff.std(ddof=1) / math.sqrt(len(diff))
        print(f"| {name} | {v.mean():.4f} | {v.mean() / base:.3f} | {diff.mean():+.3f} ± {se:.3f} | "
              f"{np.mean(share[name]):.3f} |")


if __name__ == "__main__":
    main()
