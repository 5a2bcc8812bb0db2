"""The pictures of a comparison: xylem's mean, Mitsuba's mean, their difference and the z map."""

import numpy as np


def srgb(x):
    """Linear → sRGB transfer (IEC 61966-2-1)."""
    x = np.clip(x, 0.0, 1.0)
    return np.where(x <= 0.0031308, 12.92 * x, 1.055 * np.power(x, 1 / 2.4) - 0.055)


def diverging(v, limit):
    """v / limit in [−1, 1] as blue (−) – white (0) – red (+)."""
    t = np.clip(v / limit, -1.0, 1.0)[..., None]
    white, red, blue = np.ones(3), np.array([0.8, 0.1, 0.1]), np.array([0.1, 0.2, 0.8])
    return np.where(t >= 0, white + t * (red - white), white - t * (blue - white))


def upscale(img, factor):
    return np.repeat(np.repeat(img, factor, axis=0), factor, axis=1)


def panel(result, block, z_limit=6.0):
    """[xylem | Mitsuba | difference (luminance, ±10 % of the mean) | pixel z (max over channels,
    ±z_limit) | region z] side by side, 8-bit RGB; tiles upscaled to at least 128 px high."""
    px, rg = result["pixels"], result[f"{block}x{block} regions"]
    mx, mm = px["mean_x"], px["mean_m"]
    lum = np.array([0.2126, 0.7152, 0.0722])
    scale = 1.0 / max(np.percentile(mm @ lum, 99), 1e-9)
    diff = (mx - mm) @ lum
    zpix = np.take_along_axis(px["z"], np.abs(px["z"]).argmax(-1)[..., None], -1)[..., 0]
    zreg = np.take_along_axis(rg["z"], np.abs(rg["z"]).argmax(-1)[..., None], -1)[..., 0]
    zreg = upscale(zreg, block)
    h, w = mx.shape[:2]
    zreg_full = np.zeros((h, w))
    zreg_full[:zreg.shape[0], :zreg.shape[1]] = zreg
    tiles = [srgb(mx * scale), srgb(mm * scale),
             diverging(np.nan_to_num(diff), 0.1 * max(float((mm @ lum).mean()), 1e-9)),
             diverging(np.nan_to_num(zpix, posinf=z_limit, neginf=-z_limit), z_limit),
             diverging(np.nan_to_num(zreg_full, posinf=z_limit, neginf=-z_limit), z_limit)]
    factor = max(1, -(-128 // h))
    gap = np.ones((h * factor, 4, 3))
    row = []
    for t in tiles:
        row += [upscale(t, factor), gap]
    return (np.concatenate(row[:-1], axis=1) * 255 + 0.5).astype(np.uint8)


def write_png(mi, path, rgb8):
    mi.Bitmap(np.ascontiguousarray(rgb8)).write(path)
