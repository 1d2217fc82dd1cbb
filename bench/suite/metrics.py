"""Error metrics of the suite (docs/design.md, "Metrics").

- relMSE on linear radiance: mean over pixels and channels of (I - R)^2 / (R^2 + 0.01);
- LDR-FLIP on the tonemapped sRGB image (the renderer's documented PNG transform, below) and
  HDR-FLIP on linear radiance, both from NVIDIA's official implementation (flip-evaluator);
- temporal flicker: mean MSE between consecutive frames of a static camera, jitter off.
"""
import numpy as np

try:
    import flip_evaluator as flip
except ImportError:  # pragma: no cover - the setup script installs it
    flip = None


def load_exr(path):
    """Linear RGB float32 array (H, W, 3) of an EXR written by rtpg."""
    if flip is None:
        raise RuntimeError("flip-evaluator is not installed (bash tools/setup.sh)")
    return np.asarray(flip.load(str(path)), dtype=np.float32)[..., :3]


def tonemap_srgb(radiance, exposure=1.0):
    """The PNG transform of rtpg (kernels/shared/tonemap.h): exposure, Narkowicz's ACES fit,
    sRGB transfer function; values in [0, 1]. Non-finite values become 0."""
    x = np.nan_to_num(np.asarray(radiance, dtype=np.float64) * exposure, nan=0.0, posinf=0.0, neginf=0.0)
    x = np.maximum(x, 0.0)
    y = np.clip((x * (2.51 * x + 0.03)) / (x * (2.43 * x + 0.59) + 0.14), 0.0, 1.0)
    return np.where(y <= 0.0031308, 12.92 * y, 1.055 * np.power(y, 1.0 / 2.4) - 0.055).astype(np.float32)


def key_exposure(reference):
    """The exposure a scene file records (scenes/README.md, "exposure"): the one that puts the
    reference's log-average luminance over its lit pixels (luminance above 1e-4; an open sky or
    background of zero would drag the average to black) at Reinhard's key 0.18, rounded to a
    power of two (whole photographic stops). A property of the reference alone, never of a
    method's image."""
    r = np.asarray(reference, dtype=np.float64)
    luminance = 0.2126 * r[..., 0] + 0.7152 * r[..., 1] + 0.0722 * r[..., 2]
    lit = luminance[np.isfinite(luminance) & (luminance > 1e-4)]
    if lit.size == 0:
        raise ValueError("the reference has no lit pixel")
    return float(2.0 ** np.round(np.log2(0.18 / np.exp(np.mean(np.log(lit))))))


def relmse(image, reference):
    image = np.asarray(image, dtype=np.float64)
    reference = np.asarray(reference, dtype=np.float64)
    return float(np.mean((image - reference) ** 2 / (reference ** 2 + 0.01)))


def flip_ldr(image, reference, exposure=1.0):
    """Mean LDR-FLIP of the tonemapped images (0 = identical); exposure: the scene's
    (runner.scene_exposure), as its PNG output shows it."""
    _, mean, _ = flip.evaluate(tonemap_srgb(reference, exposure), tonemap_srgb(image, exposure), "LDR")
    return float(mean)


def flip_hdr(image, reference):
    """Mean HDR-FLIP of linear radiance (exposure range chosen by FLIP from the reference)."""
    ref = np.nan_to_num(np.asarray(reference, dtype=np.float32))
    img = np.nan_to_num(np.asarray(image, dtype=np.float32))
    _, mean, _ = flip.evaluate(ref, img, "HDR")
    return float(mean)


def flicker(frames):
    """Mean MSE between consecutive frames (list of arrays)."""
    if len(frames) < 2:
        return 0.0
    return float(np.mean([np.mean((a.astype(np.float64) - b) ** 2) for a, b in zip(frames[1:], frames[:-1])]))


def downsample_box(image, factor):
    """Mean of each factor x factor block. rtpg's pixel filter is a box (uniform sub-pixel jitter
    through a pinhole camera, linear in raster position), so the block mean of a reference at
    (f W) x (f H) is an unbiased reference at W x H with f^2 times its samples per pixel."""
    image = np.asarray(image, dtype=np.float64)
    h, w = image.shape[0] // factor, image.shape[1] // factor
    if h * factor != image.shape[0] or w * factor != image.shape[1]:
        raise ValueError(f"{image.shape[1]}x{image.shape[0]} is not a multiple of {factor}")
    return image.reshape(h, factor, w, factor, -1).mean(axis=(1, 3)).astype(np.float32)


def paired_ratio(base, other):
    """Two runs that filtered or rendered the same frames (same seeds, one setting changed), frame
    by frame: values base[i] and other[i] of frame i (None where a run has none). Returns the ratio
    of the means, the mean of the per-frame ratios other / base with its standard error, how many
    frames are higher in `other`, and the number of pairs. Paired, the frames' common noise cancels:
    docs/denoising.md, "The rest of the suite" resolves a kernel change this way that the two runs'
    own standard errors do not. Frames where base is 0 are left out of the per-frame ratios."""
    pairs = [(a, b) for a, b in zip(base, other) if a is not None and b is not None]
    if not pairs:
        raise ValueError("no frame has a value in both runs")
    ratios = [b / a for a, b in pairs if a != 0]
    mean_ratio = float(np.mean(ratios)) if ratios else float("nan")
    sem = float(np.std(ratios, ddof=1) / np.sqrt(len(ratios))) if len(ratios) > 1 else float("nan")
    mean_base = float(np.mean([a for a, _ in pairs]))
    ratio_of_means = float(np.mean([b for _, b in pairs])) / mean_base if mean_base != 0 else float("nan")
    higher = sum(1 for a, b in pairs if b > a)
    return {"mean_base": mean_base, "mean_other": float(np.mean([b for _, b in pairs])),
            "ratio_of_means": ratio_of_means, "mean_ratio": mean_ratio, "sem": sem, "higher": higher,
            "pairs": len(pairs)}
