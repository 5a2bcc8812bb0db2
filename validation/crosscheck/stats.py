"""Do two renderers converge to the same image? Per-pixel and per-region two-sample tests on
independent batches.

Each renderer renders n batches with different seeds. Per pixel (and channel) the batch means
give a mean m and a sample variance s² (of one batch's value), and

    z = (m_x − m_m) / sqrt(s_x² / n_x + s_m² / n_m),

the statistic of Mitsuba 3's image regression tests (src/render/tests/test_render.py: |mean −
ref| · sqrt(spp / var), two-sided p, Šidák-corrected over the pixels) with the variance of both
images, since neither is a converged reference. With 8–16 batches the variances are estimates, so
p is Welch's t-test's (Welch 1947; its use for renderers: Jung, Hanika and Dachsbacher 2020,
"Detecting bias in Monte Carlo renderers using Welch's t-test", JCGT 9(2)): z against Student's
t with the Welch–Satterthwaite degrees of freedom. A family of N tests (all pixel channels, or all
region channels) passes at level α when its smallest p exceeds the Šidák level
1 − (1 − α)^(1/N) (Šidák 1967).
"""

import math

import numpy as np

_lgamma = np.vectorize(math.lgamma, otypes=[float])


def _betacf(a, b, x, iterations=500, eps=1e-13):
    """Continued fraction of the incomplete beta function, modified Lentz's method (Numerical
    Recipes 3rd ed. §6.4, eq. 6.4.5), element-wise, until every element has converged."""
    tiny = 1e-300
    fix = lambda v: np.where(np.abs(v) < tiny, tiny, v)
    qab, qap, qam = a + b, a + 1.0, a - 1.0
    c = np.ones_like(x)
    d = 1.0 / fix(1.0 - qab * x / qap)
    h = d.copy()
    for m in range(1, iterations + 1):
        m2 = 2 * m
        step = np.ones_like(x)
        for aa in (m * (b - m) * x / ((qam + m2) * (a + m2)),
                   -(a + m) * (qab + m) * x / ((a + m2) * (qap + m2))):
            d = 1.0 / fix(1.0 + aa * d)
            c = fix(1.0 + aa / c)
            h = h * d * c
            step = d * c
        if np.all(np.abs(step - 1.0) < eps):
            break
    return h


def betainc(a, b, x):
    """The regularised incomplete beta function I_x(a, b) (Numerical Recipes §6.4, eq. 6.4.6:
    the continued fraction where it converges fast, the symmetry I_x(a,b) = 1 − I_{1−x}(b,a)
    elsewhere)."""
    a, b, x = np.broadcast_arrays(*(np.asarray(v, float) for v in (a, b, x)))
    x = np.clip(x, 0.0, 1.0)
    inner = (x > 0) & (x < 1)
    xs = np.where(inner, x, 0.5)
    front = np.exp(_lgamma(a + b) - _lgamma(a) - _lgamma(b)
                   + a * np.log(xs) + b * np.log1p(-xs))
    direct = xs < (a + 1.0) / (a + b + 2.0)
    ca, cb, cx = np.where(direct, a, b), np.where(direct, b, a), np.where(direct, xs, 1.0 - xs)
    part = front * _betacf(ca, cb, cx) / ca
    out = np.where(direct, part, 1.0 - part)
    return np.where(inner, out, np.where(x <= 0, 0.0, 1.0))


def t_two_sided(t, dof):
    """P(|T| ≥ |t|) for Student's t with `dof` degrees of freedom: I_{ν/(ν+t²)}(ν/2, 1/2)
    (Abramowitz & Stegun 26.7.1 with 26.5.27)."""
    t = np.asarray(t, float)
    dof = np.asarray(dof, float)
    with np.errstate(over="ignore", invalid="ignore"):
        x = dof / (dof + t * t)
    x = np.where(np.isinf(t), 0.0, x)
    return betainc(dof / 2.0, 0.5, x)


def welch(batches_x, batches_m):
    """z (as above), Welch–Satterthwaite degrees of freedom and two-sided p per element, from
    batch arrays of shape (n, ...). Where both variances are 0 the two values are compared
    exactly: z = 0 if equal (to 1e-6 relative), else ±∞."""
    nx, nm = len(batches_x), len(batches_m)
    mx, mm = batches_x.mean(axis=0), batches_m.mean(axis=0)
    vx, vm = batches_x.var(axis=0, ddof=1) / nx, batches_m.var(axis=0, ddof=1) / nm
    se2 = vx + vm
    diff = mx - mm
    with np.errstate(divide="ignore", invalid="ignore"):
        z = diff / np.sqrt(se2)
        dof = se2 * se2 / (vx * vx / (nx - 1) + vm * vm / (nm - 1))
    flat = se2 <= 0
    same = np.abs(diff) <= 1e-6 * np.maximum(np.abs(mx), np.abs(mm))
    z = np.where(flat, np.where(same, 0.0, np.copysign(np.inf, diff)), z)
    dof = np.where(flat | ~np.isfinite(dof), min(nx, nm) - 1.0, dof)
    p = t_two_sided(z, dof)
    return z, dof, p, mx, mm


def sidak(alpha, n):
    """The per-test level that keeps the chance of any false rejection among n at alpha."""
    return 1.0 - (1.0 - alpha) ** (1.0 / max(n, 1))


def block_means(batches, block):
    """Batch arrays (n, H, W, C) averaged over block × block pixel regions (edges cropped)."""
    n, h, w, c = batches.shape
    hb, wb = h // block, w // block
    b = batches[:, :hb * block, :wb * block].reshape(n, hb, block, wb, block, c)
    return b.mean(axis=(2, 4))


def compare(batches_x, batches_m, alpha=0.01, block=8):
    """The pixel, region and whole-image tests of two batch stacks (n, H, W, 3)."""
    out = {}
    levels = [("pixels", batches_x, batches_m),
              (f"{block}x{block} regions", block_means(batches_x, block),
               block_means(batches_m, block)),
              ("image", batches_x.mean(axis=(1, 2), keepdims=True),
               batches_m.mean(axis=(1, 2), keepdims=True))]
    for name, bx, bm in levels:
        z, dof, p, mx, mm = welch(bx, bm)
        level = sidak(alpha, p.size)
        worst = np.unravel_index(np.argmin(p), p.shape)
        out[name] = {
            "tests": int(p.size), "max_abs_z": float(np.max(np.abs(z))),
            "min_p": float(np.min(p)), "level": level, "pass": bool(np.min(p) > level),
            "worst": {"index": [int(i) for i in worst], "z": float(z[worst]),
                      "dof": float(dof[worst]), "mean_xylem": float(mx[worst]),
                      "mean_mitsuba": float(mm[worst])},
            "z": z, "p": p, "mean_x": mx, "mean_m": mm,
        }
    return out
