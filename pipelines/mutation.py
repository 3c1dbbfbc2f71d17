"""Mutation testing of roughsea_torch: does the test suite notice a wrong physical number?

Each mutant changes one thing in one function of the package: a numeric constant (×1.01 for a
float, ±1 for an int in arithmetic), an arithmetic operator (+ ↔ −, * ↔ /), an exponent (+1), a
comparison (< ↔ <=, > ↔ >=, == ↔ !=), a dropped term (a ± b → a), a dropped unary minus, a dropped
degree→radian conversion (``deg2rad``/``radians``/``* d2r``), or two swapped arguments
(``atan2``, ``where``, ``minimum``/``maximum`` …). For every mutant the module's test files (the
mapping below) run with ``pytest -x -q`` in a COPY of the repository, with ``PYTHONPATH`` at the
copy (checked: the copy's package is the one imported), so /work/main is never touched. Mutants run
on ``--workers`` processes in parallel (one private copy each), with a timeout per mutant.

Outcomes: killed (a test failed), survived (all passed), timeout, error (the mutant could not be
imported: counted as killed, pytest reports it as an error). Tests that already fail on the
unmutated copy are deselected first (others may be mid-rewrite), and the report says so.

Results are merged by module into ``docs/mutation.md`` (the state is a comment block at its end),
rewritten from every module's latest results: per-module and overall kill rates, and every survivor
with its diff line and a note (the notes live in ``NOTES`` below, keyed by module and diff line).

    python pipelines/mutation.py --modules slopes optics radiometry --max-per-module 12 --workers 1
    python pipelines/mutation.py --modules renderer --max-per-module 8          # every renderer/ module
    python pipelines/mutation.py --modules all --max-per-module 8               # every module (hours)
    python pipelines/mutation.py --modules sun --max-per-module 12 --only-survivors
    python pipelines/mutation.py --modules sampling --only-survivors --match "sample\\(\\)"  # those of one function
    python pipelines/mutation.py --list --modules expectation        # show the mutants only
"""

from __future__ import annotations

import argparse
import ast
import copy
import json
import os
import random
import re
import shutil
import subprocess
import sys
import tempfile
import time
from concurrent.futures import ThreadPoolExecutor
from dataclasses import asdict, dataclass, field
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
PKG = "roughsea_torch"

# The test files that check each module's numbers, the module's own mirrored file first, then those
# whose tests exercise it (``-x`` stops at the first failure, so the most discriminating go first).
# Not used: tests/test_golden.py (it compares renders bit for bit with saved renders of this same
# code: it fails on ANY change, whether or not a physical number is checked, so it would hide every
# survivor the mutation pass exists to find), tests/test_readme.py and tests/test_examples.py (run the
# README's and the examples' code) and tests/test_architecture.py (the import layers, not numbers).
# the physics core: the expectation, the slope law, optics, radiometry, skies, quadrature
CORE = ["tests/test_expectation.py", "tests/test_optics.py", "tests/test_slopes.py", "tests/test_radiometry.py",
        "tests/test_sky.py", "tests/test_atmosphere.py", "tests/test_validation.py", "tests/test_quadrature.py"]
# the renderer's expectation images: scenes, cameras, the table against per-pixel evaluation
RENDER = ["tests/renderer/test_scene.py", "tests/renderer/test_api.py", "tests/test_geometry.py",
          "tests/renderer/test_pixels.py", "tests/renderer/test_sky_terms.py", "tests/renderer/test_table.py",
          "tests/renderer/test_path.py", "tests/test_sensitivity.py", "tests/renderer/test_coordinates.py",
          "tests/renderer/test_output.py"]
# the sun, its glint and the day sky in renders
DAY = ["tests/test_sun.py", "tests/renderer/test_glint.py", "tests/renderer/test_sky_terms.py"]
# the wave field and what the textured renderer makes of it
WAVES = ["tests/test_waves.py", "tests/test_wave_lattice.py", "tests/test_wave_bands.py", "tests/test_clutter.py",
         "tests/test_foam.py", "tests/renderer/test_texture.py"]
ATM = ["tests/test_atmosphere.py", "tests/test_lowtran.py", "tests/test_observer_sky.py", "tests/test_solar.py",
       "tests/test_daysky.py"]
AUGMENT = ["tests/test_augmentation.py", "tests/test_augmentation_checks.py", "tests/test_sampling.py",
           "tests/test_parameter_render.py", "tests/test_motion.py"]


def _first(own: str | list[str], *groups: list[str]) -> list[str]:
    """The module's own test file(s) first, then each group's files once, in order."""
    out: list[str] = []
    for f in ([own] if isinstance(own, str) else own) + [f for g in groups for f in g]:
        if f not in out:
            out.append(f)
    return out


TESTS: dict[str, list[str]] = {
    # foundations
    "_validation": _first("tests/test_validation.py", CORE, ["tests/renderer/test_scene.py", "tests/test_waves.py"]),
    "_parallel": _first("tests/test_parallel.py", ["tests/test_clutter.py"]),
    "_lookup": _first(["tests/test_radiometry.py", "tests/test_observer_sky.py"], ATM),
    "_tables": _first(["tests/test_solar.py", "tests/test_daysky.py"], ATM),
    "_sensor_common": _first("tests/test_sensor.py", ["tests/test_sensor_noise.py", "tests/test_augmentation.py"]),
    "_augmentation_checks": _first("tests/test_augmentation_checks.py", AUGMENT),
    # physics
    "radiometry": _first("tests/test_radiometry.py", CORE, ["tests/test_sensitivity.py", "tests/test_sensor.py"]),
    "slopes": _first("tests/test_slopes.py", CORE, ["tests/test_sun.py"]),
    "optics": _first("tests/test_optics.py", CORE, ["tests/test_sun.py", "tests/renderer/test_scene.py"]),
    "sky": _first("tests/test_sky.py", CORE, ["tests/test_lowtran.py"], RENDER),
    "geometry": _first("tests/test_geometry.py", RENDER, ["tests/test_dataset_config.py"]),
    "facets": _first("tests/test_expectation.py", CORE, ["tests/test_sun.py", "tests/reference/test_sun.py"]),
    "quadrature": _first("tests/test_quadrature.py", CORE),
    "expectation": _first("tests/test_expectation.py", CORE, ["tests/test_sun.py"]),
    "atmosphere": _first("tests/test_atmosphere.py", ATM, ["tests/test_expectation.py", "tests/test_radiometry.py"], RENDER),
    "lowtran": _first("tests/test_lowtran.py", ATM, RENDER),
    "observer_sky": _first("tests/test_observer_sky.py", ATM, RENDER),
    "solar": _first("tests/test_solar.py", ATM, DAY),
    "daysky": _first("tests/test_daysky.py", ATM, DAY),
    "spectrum": _first("tests/test_spectrum.py", WAVES),
    "wave_bands": _first("tests/test_wave_bands.py", WAVES),
    "wave_lattice": _first("tests/test_wave_lattice.py", WAVES),
    "waves": WAVES,
    "sun": _first("tests/test_sun.py", DAY, ["tests/reference/test_sun.py"]),
    "foam": _first("tests/test_foam.py", ["tests/renderer/test_scene.py", "tests/renderer/test_foam_terms.py"], DAY),
    "clutter": _first("tests/test_clutter.py", ["tests/test_foam.py", "tests/renderer/test_texture.py", "tests/test_sun.py"]),
    "raytrace_surface": _first("tests/test_raytrace.py", []),
    "raytrace": _first("tests/test_raytrace.py", []),
    # renderer
    "renderer/api": _first("tests/renderer/test_api.py", RENDER, ["tests/test_parallel.py"]),
    "renderer/scene": _first("tests/renderer/test_scene.py", RENDER),
    "renderer/plan": _first("tests/renderer/test_plan.py", RENDER, DAY, ["tests/test_clutter.py"]),
    "renderer/coordinates": _first("tests/renderer/test_coordinates.py", RENDER, DAY),
    "renderer/spectral": _first("tests/renderer/test_table.py", RENDER, DAY),
    "renderer/sky_terms": _first("tests/renderer/test_sky_terms.py", RENDER, DAY),
    "renderer/path": _first("tests/renderer/test_path.py", RENDER),
    "renderer/foam_terms": _first("tests/renderer/test_foam_terms.py", RENDER, ["tests/test_foam.py"]),
    "renderer/glint": _first("tests/renderer/test_glint.py", DAY, ["tests/test_augmentation.py"]),
    "renderer/texture": _first("tests/renderer/test_texture.py", ["tests/test_clutter.py", "tests/test_foam.py"], DAY),
    "renderer/hits": _first("tests/renderer/test_hits.py", ["tests/renderer/test_texture.py"]),
    "renderer/swept": _first("tests/renderer/test_hits.py", ["tests/renderer/test_texture.py", "tests/renderer/test_lean.py"]),
    "renderer/lean": _first("tests/renderer/test_lean.py"),
    "renderer/antialias": _first("tests/renderer/test_antialias.py", ["tests/renderer/test_texture.py", "tests/test_clutter.py",
                                                                       "tests/test_foam.py"]),
    "renderer/table": _first("tests/renderer/test_table.py", RENDER, DAY, ["tests/test_clutter.py"]),
    "renderer/pixels": _first("tests/renderer/test_pixels.py", RENDER),
    "renderer/direct": _first("tests/renderer/test_table.py", RENDER, DAY, ["tests/test_clutter.py"]),
    "renderer/output": _first("tests/renderer/test_output.py", RENDER),
    "renderer/settings": _first("tests/renderer/test_settings.py", RENDER),
    # applications
    "motion": _first("tests/test_motion.py", AUGMENT, ["tests/test_dataset.py"]),
    "sensitivity": _first("tests/test_sensitivity.py", RENDER),
    "sensor": _first("tests/test_sensor.py", ["tests/test_sensor_noise.py", "tests/test_augmentation.py"]),
    "sensor_noise": _first("tests/test_sensor_noise.py", ["tests/test_sensor.py", "tests/test_augmentation.py"]),
    "sampling": _first("tests/test_sampling.py", AUGMENT, ["tests/test_dataset.py"]),
    "parameter_render": _first("tests/test_parameter_render.py", AUGMENT, ["tests/test_dataset.py"]),
    "augmentation": _first("tests/test_augmentation.py", AUGMENT),
    "dataset_config": _first("tests/test_dataset_config.py", ["tests/test_dataset.py", "tests/renderer/test_scene.py"]),
    "dataset": _first("tests/test_dataset.py", ["tests/test_dataset_config.py"]),
    # reference (numpy)
    "reference/planck": _first("tests/test_radiometry.py", ["tests/test_expectation.py", "tests/test_optics.py"]),
    "reference/fresnel": _first("tests/test_optics.py", ["tests/test_expectation.py", "tests/test_foam.py",
                                                          "tests/reference/test_sun.py"]),
    "reference/slopes": _first("tests/test_slopes.py", ["tests/test_expectation.py", "tests/reference/test_sun.py"]),
    "reference/rough_sea": _first("tests/reference/test_rough_sea.py", ["tests/test_expectation.py", "tests/test_optics.py",
                                                                         "tests/reference/test_sun.py"]),
    "reference/facet_integral": _first("tests/reference/test_rough_sea.py", ["tests/test_expectation.py",
                                                                               "tests/reference/test_sun.py"]),
    "reference/foam": _first("tests/test_foam.py", []),
    "reference/sun": _first("tests/reference/test_sun.py", ["tests/test_sun.py"]),
}
# Modules with nothing to mutate, or not code under test: listed so that every file of the package is accounted for.
NOT_MUTATED: dict[str, str] = {
    "__init__": "imports and __all__ only",
    "_version": "the version string only",
    "renderer/__init__": "imports and __all__ only",
    "reference/__init__": "imports and __all__ only",
    "reference/_selfcheck": ("a script that prints the reference's self-checks (python -m roughsea_torch.reference._selfcheck); "
                             "it is itself a check, asserts nothing, and no test runs it"),
}
REFERENCE = sorted(m for m in TESTS if m.startswith("reference/"))
RENDERER = sorted(m for m in TESTS if m.startswith("renderer/"))
MODULE_ALIASES = {"reference": REFERENCE, "reference/*": REFERENCE, "renderer": RENDERER, "renderer/*": RENDERER,
                  "all": list(TESTS)}

# Notes on survivors, keyed by (module, diff line): why the mutant is equivalent or changes no
# physical number, or which test now kills it. Filled in after reading each survivor.
# A key is "function() original  →  mutated", the diff line "original  →  mutated", or "original" for
# every mutant of that expression (an "L<line> " prefix is ignored: a note follows its expression).
NOTES: dict[tuple[str, str], str] = {
    ('optics', 'L222 1e-6'):
        'equivalent: the finite-difference step of the Gauss–Newton Jacobian in band_refractive_index; ×1.01 changes the converged (n, k) by < 1e-12 (the fit is checked by test_published_values::test_lwir_band_index_is_the_least_squares_optimum, which it still passes).',
    ('optics', 'L244 fresnel_terms(c, nn[..., None], kk[..., None])'):
        'changes only worst(), the test that chooses between the fitted and the averaged index; both candidates are right in their band and the choice stays the same for LWIR and MWIR (test_band_index_in_mwir_is_the_planck_weighted_average checks both choices). Not a physical number; a band where the choice flips would kill it.',
    ('radiometry', 'L141 head + ("flat",)'):
        'equivalent: part of a cache key; the other keys still differ from it in length and content.',
    ('radiometry', 'L282 1e-13 * t'):
        'equivalent: the Newton stopping test of the far-from-table inversion becomes stricter (1e-13/T instead of 1e-13·T); the iteration stops at the 60-step cap with the same value to rounding.',
    ('radiometry', 'L335 1'):
        'equivalent: one more log-L bucket past the end of the brightness-temperature table (never reached: indices are clamped to the last bucket).',
    ('radiometry', 'L360 Ld <= Ln[-1]'):
        "equivalent: a radiance exactly at the table's last node (500 K) goes to the Newton inversion instead of the table; both give 500 K to 1e-12 (test_tabulated_response_and_table_edges).",
}
NOTES[("geometry", "L141 1.0")] = ("equivalent: clamp(cos, -1, 1.01) before acos; a cosine of a unit "
                                   "vector never exceeds 1 by more than rounding.")
NOTES[("sky", "L108 2")] = ("equivalent: a bucket's first interval is clamped one interval lower at the table's "
                            "end; the compare with the next node then moves the query into the right interval "
                            "(tests/test_torch_core.py compares the lookup with scipy's PCHIP).")
NOTES[("_parallel", "L101 n <= 1")] = ("equivalent: with one thread, one_thread sets torch's thread count to 1 "
                                      "and restores it to 1 instead of returning at once; same results and settings.")
NOTES[("expectation", "L269 A * sqrt_1mB2")] = (
    "accuracy only: it moves the sky disc's outer panel limits where the Gaussian window (7.5σ) ends "
    "inside the disc, narrowing the window to about 5σ near nadir; measured over W = 0, 5, 20 m/s "
    "(isotropic and anisotropic), θ̂ = 0–89°: R_a changes by at most 5.9e-9 relative, below the "
    "float64 accuracy target (1e-6) and of the order of the documented float64 error (6.8e-9). "
    "No physical number changes at the accuracy the library promises.")
NOTES[("expectation", "L291 torch.maximum(shift(u_plus), d_m)")] = "equivalent: maximum is symmetric in its arguments."
NOTES[("reference/fresnel", "L68 1.0")] = (
    "equivalent: np.minimum(c, 1.01) where the line before has rejected c > 1 + 1e-12 (the clamp only "
    "removes rounding above 1).")
NOTES[("reference/planck", "L103 400.0")] = (
    "equivalent for every radiance inside the reference's documented 150–400 K domain: the upper end "
    "of the brentq bracket (same root); only the domain check moves from 400 K to 404 K.")
NOTES[("reference/fresnel", "L68 np.minimum(c, 1.0)")] = "equivalent: minimum is symmetric in its arguments."
NOTES[("reference/rough_sea", "L175 0.25 * tr * tr")] = (
    "accuracy only: the reference's outer truncation angle θ_max (N_RMS times the largest rms slope) "
    "becomes larger; integrating further into the Gaussian tail changes nothing beyond scipy's epsrel.")
NOTES[("reference/rough_sea", "L247 self.ph + k * HALF_PI")] = (
    "accuracy only: breakpoints handed to scipy's adaptive quad (where the shadow/sky edges enter); "
    "without them quad subdivides adaptively to the same epsrel.")
NOTES[("reference/rough_sea", "L282 0.5 * (HALF_PI - self.th)")] = (
    "accuracy only: a breakpoint hint of scipy's adaptive quad moves; the value is the same to epsrel.")
NOTES[("reference/rough_sea", "L389 1e-12")] = (
    "accuracy only: the inner tolerance of an integral whose exact value is 0 (used only there).")
# Survivors of the pass after the layout change (issue 21), reviewed one by one: what each changes, and
# measured where it is a numerical choice (accuracy only). Keys: "function() original  →  mutated", or
# "function() original" for every mutant of that expression.
NOTES[('_lookup', 'bucket_grid() float((x[1:] - x[:-1]).min()) * (1.0 - 1e-6)  →  (float((x[1:] - x[:-1]).min()) / (1.0 - 1e-06))')] = (
    'robustness margin: buckets 1e-6 wider than the smallest node spacing instead of 1e-6 narrower; a '
    'bucket can then hold a second node only within 1e-6 of a spacing past its edge, where the interval '
    'found is the C¹ cubic continued by that sliver (same value to rounding)'
)
NOTES[('_lookup', 'bucket_grid() 1.0  →  (1.01)')] = (
    'robustness margin, measured: with buckets 1.01 node spacings wide, sky tables of 50, 200 and 1000 '
    "nodes (uniform and jittered, 50 queries an interval) still match scipy's PCHIP to 3e-14 (a misplaced "
    "query lies within 1 % of a spacing past its interval's end, where the C¹ cubic continued gives the "
    'same value)'
)
NOTES[('_tables', 'check_band_coverage() band.lo < lo * (1 - 1e-9)')] = (
    'argument check only: the bound of a ValueError (which inputs are refused), no computed value changes '
    "(the 1e-9 relative tolerance at the table's spectral edges)"
)
NOTES[('_tables', 'check_band_coverage() lo * (1 - 1e-9)')] = (
    'argument check only: the bound of a ValueError (which inputs are refused), no computed value changes '
    "(the 1e-9 relative tolerance at the table's spectral edges)"
)
NOTES[('_tables', 'check_band_coverage() 1e-9')] = (
    'argument check only: the bound of a ValueError (which inputs are refused), no computed value changes '
    "(the 1e-9 relative tolerance at the table's spectral edges)"
)
NOTES[('_tables', 'check_band_coverage() band.hi > hi * (1 + 1e-9)')] = (
    'argument check only: the bound of a ValueError (which inputs are refused), no computed value changes '
    "(the 1e-9 relative tolerance at the table's spectral edges)"
)
NOTES[('_tables', 'check_band_coverage() 1 + 1e-9')] = (
    'argument check only: the bound of a ValueError (which inputs are refused), no computed value changes '
    "(the 1e-9 relative tolerance at the table's spectral edges)"
)
NOTES[('_sensor_common', 'check_pair() a < b')] = (
    'argument check only: the bound of a ValueError (which inputs are refused), no computed value changes '
    '(a (low, high) pair with low = high accepted)'
)
NOTES[('_augmentation_checks', 'check_input() 1.0  →  (1.01)')] = (
    'argument check only: the bound of a ValueError (which inputs are refused), no computed value changes '
    '(an alpha channel up to 1.01 accepted)'
)
NOTES[('_augmentation_checks', 'check_params() atm < len(atmospheres)')] = (
    'argument check only: the bound of a ValueError (which inputs are refused), no computed value changes '
    '(an atmosphere index one past the list fails later, at its use)'
)
NOTES[('_augmentation_checks', 'check_params() params[k] < 0')] = (
    'argument check only: the bound of a ValueError (which inputs are refused), no computed value changes '
    '(seed 0 refused)'
)
NOTES[('quadrature', 'default() 6.0  →  (6.0600000000000005)')] = (
    "accuracy only: the float32 rule's Gaussian window 1 % wider (6.06σ); tests/test_expectation.py's "
    'float32 comparisons with the reference (1e-5) still hold'
)
NOTES[('quadrature', 'default() 7.5  →  (7.575)')] = (
    "accuracy only: the float64 rule's Gaussian window 1 % wider (7.575σ); the float64 comparisons with "
    'the reference (1e-6) still hold'
)
NOTES[('expectation', '_emissivity_numerator() (0.5 * (hi + lo))[:, None] + half[:, None] * xg  →  ((0.5 * (hi + lo))[:, None] - half[:, None] * xg)')] = (
    'equivalent: Gauss–Legendre nodes and weights are symmetric about 0, so mid − half·x visits the same '
    'nodes with the same weights'
)
NOTES[('expectation', '_reflected_ray_lambda() ry * ry  →  (ry / ry)')] = (
    "equivalent: |r_h|² divides s2 and μ = cos θ' / √(|r_h|² s2) multiplies it back; only the 1e-30 "
    'clamps see it'
)
NOTES[('lowtran', '__call__() hd <= hi * (1 + slack)')] = (
    'argument check only: the bound of a ValueError (which inputs are refused), no computed value changes '
    "(an altitude exactly at the table's top × (1 + 1e-6))"
)
NOTES[('observer_sky', '__init__() lv + 1e-9  →  (lv - 1e-09)')] = (
    'interpolation only, in five 1 m cells: those ending at a LOWTRAN level (999–1000 m, 1999–2000 m, …, '
    "in both tables) take log h instead of the below-level coordinate; the nodes' values are unchanged, "
    'LOWTRAN itself is NaN within 0.5 m of a level (no reference inside these cells), and the held-out '
    'LOWTRAN values still hold'
)
NOTES[('observer_sky', '_dip_value() 1.0  →  (1.01)')] = (
    'equivalent: clamp(h/h_min, 1e-12, 1.01) is used only where h < h_min (torch.where takes the table '
    'elsewhere), so h/h_min < 1'
)
NOTES[('observer_sky', '__call__() 2 * EARTH_RADIUS_M + hv  →  (2 * EARTH_RADIUS_M - hv)')] = (
    'error message only: the dip quoted in the ValueError'
)
NOTES[('observer_sky', '__call__() c > 1.0  →  (c >= 1.0)')] = (
    'equivalent: a cosine of exactly 1 is replaced by 1'
)
NOTES[('solar', '__init__() _LOG_FLOOR * max(self.toa, 1e-300)  →  (_LOG_FLOOR / max(self.toa, 1e-300))')] = (
    'equivalent for the shipped tables: the floor (1e-30 of the TOA value before, 1e-30/TOA after) is '
    'never reached; the smallest band irradiance at any node is 2.6e-14 of TOA (tropical LWIR)'
)
NOTES[('daysky', '__init__() abs(x[-1] - top) > 1e-9')] = (
    'argument check only: the bound of a ValueError (which inputs are refused), no computed value changes '
    "(the 1e-9 rad tolerance on a table's last node)"
)
NOTES[('waves', '_sample_points() WINDOW_HI * (1.0 + margin)  →  (WINDOW_HI / (1.0 + margin))')] = (
    'accuracy only: a band is skipped at points where its window 1 − smoothstep is ≤ 3 (2.8e-3/0.71)² ≈ '
    '5e-5 (within 0.2 % of u₁ = √2), not only where it is 0'
)
NOTES[('waves', '_runs() 1  →  (2)')] = (
    "equivalent: a run of points ends one block later (clipped to the points); the band's window is "
    'evaluated per point, 0 on the extra block'
)
NOTES[('sun', '_ellipse_probability_rays() torch.cos(phi1) * cx + torch.sin(phi1) * cy < 0')] = (
    "equivalent: an exact tie (the axis perpendicular to the centre's direction) has measure zero, except "
    'at c = 0, where the origin is inside and the angle is not used'
)
NOTES[('renderer/api', 'render() ref.ndim > 0')] = (
    'equivalent: ref (the intrinsics (B, 3, 3) or cos θ̂ (B, H, W)) is never 0-d; it only decides on one '
    'thread'
)
NOTES[('renderer/output', 'kelvin() low > 0')] = (
    'argument check only: the bound of a ValueError (which inputs are refused), no computed value changes '
    '(a radiance of exactly 0 accepted)'
)
NOTES[('renderer/texture', '_reflection_by_rule() ct > self.steep_cos')] = (
    'equivalent: a tie at the switch between the two rules, both right there (they agree within the '
    "texture table's accuracy)"
)
NOTES[('sensor_noise', '_pattern() self.offset_std_k * z_pix + self.column_std_k * z_col  →  (self.offset_std_k * z_pix - self.column_std_k * z_col)')] = (
    "equivalent in distribution: z_col is a standard normal draw and −z_col has the same law; a seed's "
    "column offsets change, their statistics (test_sensor_noise, test_sensor's typical_lwir) do not"
)
NOTES[('sampling', '_splitmix64() 0x94D049BB133111EB')] = (
    'seed hashing: a different 64-bit mixer constant gives other, equally spread per-image seeds; no '
    'physical number'
)
NOTES[('sampling', '_check_daytime() 1.0  →  (1.01)')] = (
    'argument check only: the bound of a ValueError (which inputs are refused), no computed value changes '
    '(daytime up to 1.01 accepted)'
)
NOTES[('sampling', '_motion_ranges() hi + h  →  (hi - h)')] = (
    'argument check only: the bound of a ValueError (which inputs are refused), no computed value changes '
    "(the altitude range's upper end ± heave)"
)
NOTES[('sampling', 'sample() 1  →  (2)')] = (
    'equivalent in distribution: one more row of uniforms is drawn and the phase takes another row, as '
    'uniform'
)
NOTES[('augmentation', '_selected() params["batch_prob"].reshape(-1).cpu() > 0.5')] = (
    'equivalent: the gate holds 0 or 1'
)
NOTES[('augmentation', '__batch_prob_generator__() torch.rand(n, generator=g) < p')] = (
    'equivalent in distribution: a tie of a uniform draw with p (probability 2⁻²⁴)'
)
NOTES[('augmentation', '__batch_prob_generator__() torch.rand(1, generator=g) < p_batch')] = (
    'equivalent in distribution: a tie of a uniform draw with p_batch'
)
NOTES[('augmentation', '__batch_prob_generator__() p_batch < 1.0')] = (
    'equivalent in distribution: with p_batch = 1 one more uniform is drawn (always < 1); later draws '
    'shift, their law does not'
)
NOTES[('dataset', '_finished_shards() out / shard_name(k)  →  (out * shard_name(k))')] = (
    'file handling only (a shard renamed into place before a crash, on resume); no physical number'
)
NOTES[('raytrace_surface', '_bounds() torch.stack(v, 1) * (1.0 + 1e-9) + 1e-12')] = (
    'robustness margin: the bounds lose their 1e-12 absolute slack and keep the 1e-9 relative one; steps '
    'overshoot by at most 1e-12 m'
)
NOTES[('raytrace_surface', '_bisect() mid >= hi')] = (
    "termination guard at the dtype's resolution, never reached at the tolerances used (bisection stops "
    'at tolerance_m first)'
)
NOTES[('raytrace_surface', 'march_first_hits() 1.0 - dz * dz  →  (1.0 + dz * dz)')] = (
    "conservative: overestimates the ray's horizontal speed in the closing rate −dz + L·horizontal, so "
    'the safe steps shrink (slower march, the same hits to the bisection tolerance)'
)
NOTES[('raytrace', 'raytraced_image() cz + torch.sin(vz) * s_par')] = (
    'diagnostic only: facing_away_fraction (hits whose traced facet faces away), not the radiance'
)
NOTES[('raytrace', 'raytraced_image() f_up * torch.cos(los_az)  →  (f_up / torch.cos(los_az))')] = (
    'diagnostic only: hidden_fraction (flat points hidden behind a traced facet), not the radiance'
)
NOTES[('renderer/hits', 'sweep_layout() (hf - eta_max) / tg_max  →  ((hf - eta_max) * tg_max)')] = (
    'accuracy/time only: the sweep starts nearer the camera (more samples before the first possible '
    'crest); the hits are the same'
)
NOTES[('renderer/hits', 'sweep_layout() 1.0  →  (1.01)')] = (
    'accuracy only: 1 % more samples along the sweep (a tuning density)'
)
NOTES[('renderer/coordinates', 'azimuth_centre() 2 * ps  →  (2 / ps)')] = (
    'accuracy only, measured by pipelines/mutation_accuracy.py (max relative |table − per-pixel| over 10 scenes: night anisotropic, '
    'correlated and wide; day with the glint, with and without aerosol; nadir night and day; textured '
    'night and day; and the sweep against itself): unchanged (the lifted spans about it bound the nodes)'
)
NOTES[('renderer/coordinates', 'fold_range() math.pi / 2  →  (math.pi * 2)')] = (
    'accuracy only, measured by pipelines/mutation_accuracy.py (max relative |table − per-pixel| over 10 scenes: night anisotropic, '
    'correlated and wide; day with the glint, with and without aerosol; nadir night and day; textured '
    'night and day; and the sweep against itself): unchanged'
)
NOTES[('renderer/coordinates', 'camera_spans() 0.5  →  (0.505)')] = (
    'accuracy only, measured by pipelines/mutation_accuracy.py (max relative |table − per-pixel| over 10 scenes: night anisotropic, '
    'correlated and wide; day with the glint, with and without aerosol; nadir night and day; textured '
    'night and day; and the sweep against itself): unchanged'
)
NOTES[('renderer/plan', 'make_plan() p.vx + p.vy  →  (p.vx)')] = (
    "accuracy only (ε, the zenith coordinate's grazing scale, from a wrong smallest variance), measured "
    '(max relative |table − per-pixel| over 10 scenes: night anisotropic, correlated and wide; day with '
    'the glint, with and without aerosol; nadir night and day; textured night and day; and the sweep '
    'against itself): textured night 1.4e-4 → 1.9e-4, textured day 2.4e-4 → 2.7e-4, the rest within 20 %; '
    "the textured tests' bound is 3e-4"
)
NOTES[('renderer/plan', 'make_plan() 4  →  (5)')] = (
    'accuracy only, measured by pipelines/mutation_accuracy.py (max relative |table − per-pixel| over 10 scenes: night anisotropic, '
    'correlated and wide; day with the glint, with and without aerosol; nadir night and day; textured '
    'night and day; and the sweep against itself): unchanged to 1e-3 of each error'
)
NOTES[('renderer/plan', 'make_plan() 1e-4  →  (0.000101)')] = (
    'accuracy only (the floor of ε), measured by pipelines/mutation_accuracy.py (max relative |table − per-pixel| over 10 scenes: night '
    'anisotropic, correlated and wide; day with the glint, with and without aerosol; nadir night and day; '
    'textured night and day; and the sweep against itself): unchanged'
)
NOTES[('renderer/plan', '_day_nodes_for_every_azimuth() rg_all.azimuth[1] - rg_all.azimuth[0]  →  (rg_all.azimuth[1])')] = (
    'accuracy only (whether the day tables take their whole-turn node counts; more nodes when it says '
    'yes), measured by pipelines/mutation_accuracy.py (max relative |table − per-pixel| over 10 scenes: night anisotropic, correlated and '
    'wide; day with the glint, with and without aerosol; nadir night and day; textured night and day; and '
    'the sweep against itself): day with glint 3.8e-5 → 1.9e-5, the rest unchanged'
)
NOTES[('renderer/plan', '_day_nodes_for_every_azimuth() 1  →  (2)')] = (
    'accuracy only, measured by pipelines/mutation_accuracy.py (max relative |table − per-pixel| over 10 scenes: night anisotropic, '
    'correlated and wide; day with the glint, with and without aerosol; nadir night and day; textured '
    'night and day; and the sweep against itself): nadir day 1.02e-4 → 1.19e-4 (L190) or unchanged '
    "(L191); its test's bound is 0.03 K"
)
NOTES[('renderer/spectral', 'lobatto_interp() 2  →  (3)')] = (
    'accuracy only (the fine grid overhangs 3 cells instead of 2, and e with it), measured (max relative '
    '|table − per-pixel| over 10 scenes: night anisotropic, correlated and wide; day with the glint, with '
    'and without aerosol; nadir night and day; textured night and day; and the sweep against itself): '
    'within 2 % of each error'
)
NOTES[('renderer/spectral', 'barycentric() 1e-15  →  (1.01e-15)')] = (
    'equivalent: the tolerance that treats a point as a node'
)
NOTES[('renderer/glint', 'reachable() (b2 * sgx * sgx - 2 * c2 * sgx * sgy + a2 * sgy * sgy) / det  →  ((b2 * sgx * sgx - 2 * c2 * sgx * sgy + a2 * sgy * sgy) * det)')] = (
    'accuracy/time only (which pixels may see the glint: a culling bound 6 σ past the reachable ellipse), '
    'measured by pipelines/mutation_accuracy.py (max relative |table − per-pixel| over 10 scenes: night anisotropic, correlated and wide; '
    'day with the glint, with and without aerosol; nadir night and day; textured night and day; and the '
    'sweep against itself): unchanged, the two glint scenes included'
)
NOTES[('renderer/glint', 'reachable() 2.0  →  (2.02)')] = (
    'accuracy/time only (which pixels may see the glint: a culling bound 6 σ past the reachable ellipse), '
    'measured by pipelines/mutation_accuracy.py (max relative |table − per-pixel| over 10 scenes: night anisotropic, correlated and wide; '
    'day with the glint, with and without aerosol; nadir night and day; textured night and day; and the '
    'sweep against itself): unchanged, the two glint scenes included'
)
NOTES[('renderer/glint', 'reachable() torch.sqrt(d2) - reach < 6.0  →  (torch.sqrt(d2) - reach <= 6.0)')] = (
    'accuracy/time only (which pixels may see the glint: a culling bound 6 σ past the reachable ellipse), '
    'measured by pipelines/mutation_accuracy.py (max relative |table − per-pixel| over 10 scenes: night anisotropic, correlated and wide; '
    'day with the glint, with and without aerosol; nadir night and day; textured night and day; and the '
    'sweep against itself): unchanged, the two glint scenes included'
)
NOTES[('renderer/glint', 'reachable() 6.0  →  (6.0600000000000005)')] = (
    'accuracy/time only (which pixels may see the glint: a culling bound 6 σ past the reachable ellipse), '
    'measured by pipelines/mutation_accuracy.py (max relative |table − per-pixel| over 10 scenes: night anisotropic, correlated and wide; '
    'day with the glint, with and without aerosol; nadir night and day; textured night and day; and the '
    'sweep against itself): unchanged, the two glint scenes included'
)
NOTES[('renderer/texture', '_active_nodes() 2.0  →  (2.02)')] = (
    'accuracy/time only (which texture nodes are evaluated), measured (max relative |table − per-pixel| '
    'over 10 scenes: night anisotropic, correlated and wide; day with the glint, with and without '
    'aerosol; nadir night and day; textured night and day; and the sweep against itself): unchanged'
)
NOTES[('renderer/texture', '_active_nodes() 1e-10 * suu  →  (1e-10 / suu)')] = (
    'accuracy/time only (which texture nodes are evaluated), measured (max relative |table − per-pixel| '
    'over 10 scenes: night anisotropic, correlated and wide; day with the glint, with and without '
    'aerosol; nadir night and day; textured night and day; and the sweep against itself): unchanged'
)
NOTES[('renderer/swept', '_swept_samples() 2.0 * (zeta_k - lo[i].to(dtype)) / span_z[i].to(dtype)  →  (2.0 * (zeta_k - lo[i].to(dtype)) * span_z[i].to(dtype))')] = (
    "NOT KILLED, changes a physical number of an option: the sweep (TableSize(texture_hit='first'), off "
    'by default) reads its samples at wrong table coordinates, 2e-3 relative in a 10 m/s scene; no test '
    'checks the sweep against an independent evaluation at that accuracy (per-pixel evaluation takes the '
    'flat point). Open'
)
NOTES[('renderer/table', 'azimuth_nodes() rg.centre[:, None] - shift  →  (rg.centre[:, None] + shift)')] = (
    'equivalent: every node moves by one period of R_a in φ̂ (π, or 2π by day); measured (max relative '
    '|table − per-pixel| over 10 scenes: night anisotropic, correlated and wide; day with the glint, with '
    'and without aerosol; nadir night and day; textured night and day; and the sweep against itself): '
    'unchanged'
)
NOTES[('renderer/pixels', 'table_grid() 1e-30  →  (1.01e-30)')] = (
    'equivalent: a floor against a division by zero; measured (max relative |table − per-pixel| over 10 '
    'scenes: night anisotropic, correlated and wide; day with the glint, with and without aerosol; nadir '
    'night and day; textured night and day; and the sweep against itself): unchanged'
)
NOTES[("renderer/scene", "resolved() 15e-6  →  (1.515e-05)")] = (
    "equivalent: unreachable bound; bands must lie within the water index's 2.4–15 µm, so a band's centre never "
    "exceeds 15 µm (tests/renderer/test_scene.py checks the three reachable edges of foam='auto')")
NOTES[("_augmentation_checks", "check_params() len(MOTION_FIELD_NAMES) + 1  →  (len(MOTION_FIELD_NAMES) - 1)")] = (
    "argument check only: a draw missing one motion field passes this check (the motion then fails where it is built)")
NOTES[("renderer/scene", "resolved() 1e-30  →  (1.01e-30)")] = (
    "equivalent: the floor of a sea radiance of 0 before its brightness temperature picks the water index; no "
    "radiance lies between 1e-30 and 1.01e-30 W m-2 sr-1")
NOTES[("reference/sun", "__init__() det / self.lam1  →  (det * self.lam1)")] = (
    "accuracy only: a hint to scipy's adaptive quad (the calm rule's ladder of breakpoints from the smaller eigenvalue); the integrand is unchanged")
NOTES[("reference/sun", "__init__() 1.0  →  (1.01)")] = (
    "accuracy only: a hint to scipy's adaptive quad: the calm rule's polar centre (the mirror of the mean facet normal) moves; the disk's ranges are solved "
    "in closed form about any centre and the integrand is unchanged")
NOTES[("reference/sun", "__init__() self.e1c * self.e1c + self.e2c * self.e2c  →  (self.e1c * self.e1c)")] = (
    "equivalent: _basis(p, c) puts e1 in the plane of p and c, so e2·c = 0")
NOTES[("reference/sun", "integral() self.d > self.R")] = "equivalent: a tie (the spike exactly on the disk's edge)"
NOTES[("reference/foam", "foam_emissivity() 1.0  →  (1.01)")] = (
    "equivalent for water: the cap min(1, ε_w + δ) is never reached (ε_w + δ ≤ 0.994 over every angle for "
    "the LWIR default index, 0.978 for MWIR)")
NOTES[("reference/foam", "sky_hemispherical_mean() 1e-13  →  (1.01e-13)")] = "accuracy only: scipy quad's relative tolerance"
NOTES[("reference/facet_integral", "theta_max_global() 0.25 * tr * tr - det  →  (0.25 * tr * tr)")] = (
    "accuracy only: the outer truncation angle grows (a larger eigenvalue); integrating further into the "
    "Gaussian tail changes nothing beyond scipy's epsrel")
NOTES[("reference/facet_integral", "ring_azimuths() 8.0  →  (8.08)")] = "accuracy only: a hint to scipy's adaptive quad (the ladder's growth factor)"
NOTES[("reference/facet_integral", "phi_outer() 1e-2  →  (0.0101)")] = "accuracy only: the inner integral's tolerance, 1 % tighter"
NOTES[("reference/facet_integral", "theta_outer() z - self.th  →  (z)")] = "accuracy only: a hint to scipy's adaptive quad (a breakpoint at a sky node's mirror)"
NOTES[("reference/rough_sea", "emissivity() abs(w) >= 1e-15")] = (
    "equivalent: a tie at exactly 1e-15 in the visibility of a tilted flat facet seen edge-on")
NOTES[("renderer/texture", "_read_volume() 1.0  →  (1.01)")] = (
    "accuracy only: the volume's azimuth coordinate off by 0.5 % of its span (the volume varies slowly in "
    "azimuth); measured by pipelines/mutation_accuracy.py: textured night and day errors change by < 1 %, the "
    "sweep by 3.5e-6 relative")
# How the recorded state was made (printed in the report; keep it true when re-running).
HISTORY = [
    "How this state was made: a full pass (400 mutants) ran on 2026-11-26 between 15:55 and 17:26 UTC on the",
    "code before the tests were reorganized to mirror the package (with the old test files). After merging that",
    "reorganization, the ray tracer and the column filter, the modules whose code had changed were run again in",
    "full (slopes, spectrum, waves, renderer/scene, renderer/table, renderer/texture, sampling,",
    "_augmentation_checks, and augmentation, dataset, renderer/settings, sensitivity), so were the new modules",
    "(raytrace, raytrace_surface, renderer/hits, renderer/antialias) and the numpy reference (its last run was",
    "2026-11-23, before its helpers moved), and every survivor a new test targets was re-run",
    "(`--only-survivors`); the run column gives each module's last run. The other modules' rows are from the",
    "first pass: their code has not changed since, and the reorganization moved their tests' assertions",
    "without changing them. Survivors in the renderer's table layout were applied one at a time with",
    "`pipelines/mutation_accuracy.py`, which measures the table against per-pixel evaluation over ten scenes;",
    "their notes quote it.",
]
STATE_BEGIN, STATE_END = "<!-- mutation-state (read by pipelines/mutation.py; keep)", "mutation-state -->"

# Calls whose arguments are input checks (bounds, names, messages): not mutated.
SKIP_CALLS = {"check_finite_range", "ValueError", "TypeError", "RuntimeError", "print", "warn", "per_batch",
              # argument checks, by module: facets, radiometry, _sensor_common, geometry, lowtran, solar, waves,
              # spectrum, renderer/path, renderer/scene, sampling, sensor, augmentation, dataset_config,
              # _augmentation_checks, _validation, _tables, reference/*
              "_check_angles", "_check_slopes", "_check_radiance", "check_image", "check_int", "check_pair",
              "check_pose", "check_band", "check_dtype", "_check_name", "check_time", "check_wind_speed",
              "check_wave_age", "check_path_altitude", "check_foam", "_check_daytime", "_check_display_args",
              "_check_keywords", "_check_keys", "check_input", "check_params", "check_output_settings",
              "check_same_device", "check_band_coverage", "_check_band", "check_view", "check_slope_arrays",
              "check_slope_mean", "_check"}
SKIP_FUNCS = {"__repr__", "__post_init__", "extra_repr", "fmt", "__hash__", "main"}
# Calls whose first two arguments (the 2nd and 3rd of ``where``) are swapped: symmetric-looking
# physics calls where an order mistake gives a plausible wrong number.
SWAP_CALLS = {"atan2", "where", "minimum", "maximum", "logaddexp", "hypot", "arctan2", "clamp", "complex", "interp",
              "broadcast_arrays", "searchsorted", "fresnel_terms", "_planck", "planck_radiance",
              "planck_radiance_derivative", "from_variances", "SlopeStatistics", "split_refractive_index",
              "facet_geometry", "band_radiance", "_band_scalar", "glint_from_moments", "glint_sharp_factor",
              "crest_fraction_from_variances", "slope_pdf", "fresnel_reflectance", "normal_cdf", "band_index_lookup",
              "shifted", "lerp"}
DEG_CALLS = {"deg2rad", "radians"}


@dataclass
class Mutant:
    module: str
    index: int
    kind: str
    line: int
    function: str
    original: str
    mutated: str
    status: str = "pending"
    seconds: float = 0.0
    killed_by: str = ""

    @property
    def diff(self) -> str:
        return f"L{self.line} {self.original}  →  {self.mutated}"


def module_path(module: str) -> Path:
    return Path(PKG) / (module + ".py")


def unmapped(root: Path = ROOT) -> list[str]:
    """Modules of the package that are in neither TESTS nor NOT_MUTATED (the map must follow the layout)."""
    mods = [str(p.relative_to(root / PKG).with_suffix("")) for p in sorted((root / PKG).rglob("*.py"))]
    return [m for m in mods if m not in TESTS and m not in NOT_MUTATED]


def missing_test_files(root: Path = ROOT) -> list[str]:
    """Test files named in TESTS that do not exist (the map must follow the tests' layout)."""
    return sorted({f for files in TESTS.values() for f in files if not (root / f).is_file()})


# -- mutant generation -------------------------------------------------------------------------------


class _Finder(ast.NodeVisitor):
    """Collects (node, kind, new_node) candidates inside functions, outside validation/messages."""

    def __init__(self) -> None:
        self.out: list[tuple[ast.AST, str, ast.AST, str]] = []
        self.func: list[str] = []
        self.skip = 0

    def generic_visit(self, node: ast.AST) -> None:
        super().generic_visit(node)

    def visit_FunctionDef(self, node: ast.FunctionDef) -> None:
        if node.name in SKIP_FUNCS:
            return
        self.func.append(node.name)
        body = node.body
        if body and isinstance(body[0], ast.Expr) and isinstance(getattr(body[0], "value", None), ast.Constant):
            body = body[1:]  # docstring
        for stmt in body:
            self.visit(stmt)
        self.func.pop()

    visit_AsyncFunctionDef = visit_FunctionDef

    def visit_ClassDef(self, node: ast.ClassDef) -> None:
        for stmt in node.body:
            if isinstance(stmt, (ast.FunctionDef, ast.AsyncFunctionDef)):
                self.visit(stmt)

    def _skip_subtree(self, node: ast.AST) -> None:
        return  # do not descend

    visit_Raise = _skip_subtree
    visit_Assert = _skip_subtree
    visit_JoinedStr = _skip_subtree

    def visit_Call(self, node: ast.Call) -> None:
        name = _call_name(node.func)
        if name in SKIP_CALLS:
            return
        if self.func and name in DEG_CALLS and len(node.args) == 1:
            self.add(node, "deg2rad dropped", node.args[0])
        if self.func and name in SWAP_CALLS and len(node.args) >= 2:
            i, j = (1, 2) if name == "where" and len(node.args) == 3 else (0, 1)
            new = copy.deepcopy(node)
            new.args[i], new.args[j] = new.args[j], new.args[i]
            if ast.dump(new.args[i]) != ast.dump(new.args[j]):
                self.add(node, "arguments swapped", new)
        self.generic_visit(node)

    def visit_Subscript(self, node: ast.Subscript) -> None:
        self.visit(node.value)  # indices and slices are not physical numbers

    def visit_AnnAssign(self, node: ast.AnnAssign) -> None:
        if node.value is not None:
            self.visit(node.value)

    def visit_Constant(self, node: ast.Constant) -> None:
        if not self.func or isinstance(node.value, bool) or not isinstance(node.value, (int, float)):
            return
        if isinstance(node.value, float):
            if node.value != 0.0:
                self.add(node, "constant ×1.01", ast.Constant(node.value * 1.01))
        elif getattr(node, "_arith", False):
            self.add(node, "constant +1", ast.Constant(node.value + 1))

    def visit_BinOp(self, node: ast.BinOp) -> None:
        for side in (node.left, node.right):
            if isinstance(side, ast.Constant):
                side._arith = True  # type: ignore[attr-defined]
        if self.func:
            swap = {ast.Add: ast.Sub, ast.Sub: ast.Add, ast.Mult: ast.Div, ast.Div: ast.Mult}
            op = type(node.op)
            if op in swap:
                new = copy.deepcopy(node)
                new.op = swap[op]()
                self.add(node, "operator swapped", new)
            if op in (ast.Add, ast.Sub) and not _is_const(node.left) and not _is_const(node.right):
                self.add(node, "term dropped", copy.deepcopy(node.left))
            if op is ast.Pow and isinstance(node.right, ast.Constant) and isinstance(node.right.value, (int, float)):
                new = copy.deepcopy(node)
                new.right = ast.Constant(node.right.value + 1)
                self.add(node, "exponent changed", new)
                node.right._arith = False  # type: ignore[attr-defined]  # covered by the line above
            if op is ast.Mult and any(_name(s) in {"d2r", "DEG"} for s in (node.left, node.right)):
                keep = node.left if _name(node.right) in {"d2r", "DEG"} else node.right
                self.add(node, "deg2rad dropped", copy.deepcopy(keep))
        self.generic_visit(node)

    def visit_UnaryOp(self, node: ast.UnaryOp) -> None:
        if self.func and isinstance(node.op, ast.USub) and not isinstance(node.operand, ast.Constant):
            self.add(node, "unary minus dropped", copy.deepcopy(node.operand))
        self.generic_visit(node)

    def visit_Compare(self, node: ast.Compare) -> None:
        if self.func and len(node.ops) == 1:
            flip = {ast.Lt: ast.LtE, ast.LtE: ast.Lt, ast.Gt: ast.GtE, ast.GtE: ast.Gt, ast.Eq: ast.NotEq, ast.NotEq: ast.Eq}
            op = type(node.ops[0])
            if op in flip:
                new = copy.deepcopy(node)
                new.ops = [flip[op]()]
                self.add(node, "comparison changed", new)
        self.generic_visit(node)

    def add(self, node: ast.AST, kind: str, new: ast.AST) -> None:
        self.out.append((node, kind, new, self.func[-1] if self.func else "<module>"))


def _call_name(f: ast.AST) -> str:
    if isinstance(f, ast.Name):
        return f.id
    if isinstance(f, ast.Attribute):
        return f.attr
    return ""


def _name(n: ast.AST) -> str:
    return n.id if isinstance(n, ast.Name) else ""


def _is_const(n: ast.AST) -> bool:
    return isinstance(n, ast.Constant)


def _replace(src: bytes, node: ast.AST, text: str) -> bytes:
    """Replace the span of ``node`` (line/col offsets are UTF-8 byte offsets) with ``text``."""
    lines = src.splitlines(keepends=True)
    starts = [0]
    for ln in lines:
        starts.append(starts[-1] + len(ln))
    a = starts[node.lineno - 1] + node.col_offset
    b = starts[node.end_lineno - 1] + node.end_col_offset
    return src[:a] + text.encode() + src[b:]


def mutants_of(module: str, max_n: int, seed: int, root: Path = ROOT) -> tuple[list[Mutant], dict[int, bytes]]:
    path = root / module_path(module)
    src = path.read_bytes()
    tree = ast.parse(src)
    f = _Finder()
    f.visit(tree)
    seen: set[tuple[int, str]] = set()
    cands = []
    for node, kind, new, func in f.out:
        original = ast.get_source_segment(src.decode(), node) or ast.unparse(node)
        text = "(" + ast.unparse(new) + ")"
        mutated = _replace(src, node, text)
        try:
            ast.parse(mutated)
        except SyntaxError:
            continue
        key = (node.lineno, text + original)
        if key in seen or mutated == src:
            continue
        seen.add(key)
        cands.append((node.lineno, kind, func, " ".join(original.split()), " ".join(text.split()), mutated))
    rng = random.Random(f"{seed}:{module}")
    if len(cands) > max_n:
        cands = rng.sample(cands, max_n)
    cands.sort(key=lambda c: c[0])
    muts, sources = [], {}
    for i, (line, kind, func, orig, text, mutated) in enumerate(cands):
        muts.append(Mutant(module, i, kind, line, func, orig, text))
        sources[i] = mutated
    return muts, sources


# -- running ----------------------------------------------------------------------------------------


def copy_tree(dst: Path) -> Path:
    ignore = shutil.ignore_patterns(".venv", ".git", "__pycache__", "*.egg-info", "outputs", ".pytest_cache")
    shutil.copytree(ROOT, dst, ignore=ignore)
    return dst


def env_for(copy_root: Path) -> dict[str, str]:
    env = dict(os.environ)
    env["PYTHONPATH"] = str(copy_root)
    env["OMP_NUM_THREADS"] = env["MKL_NUM_THREADS"] = "1"
    env["PYTHONDONTWRITEBYTECODE"] = "1"
    return env


def check_import(copy_root: Path) -> None:
    out = subprocess.run([sys.executable, "-c", f"import {PKG}, {PKG}.reference; print({PKG}.__file__)"],
                         cwd=copy_root, env=env_for(copy_root), capture_output=True, text=True, timeout=300)
    where = Path(out.stdout.strip()).resolve() if out.returncode == 0 else None
    if where is None or copy_root.resolve() not in where.parents:
        raise SystemExit(f"the copy's package is not the one imported: {out.stdout.strip() or out.stderr[-500:]}")


def pytest_cmd(tests: list[str], deselect: list[str], timeout: float | None = None) -> list[str]:
    cmd = [sys.executable, "-m", "pytest", "-x", "-q", "-p", "no:cacheprovider", "-p", "no:randomly", "-rfE",
           "--no-header", *tests]
    for d in deselect:
        cmd += ["--deselect", d]
    return cmd


def run_tests(copy_root: Path, tests: list[str], deselect: list[str], timeout: float, stop_first: bool = True) -> tuple[str, float, str]:
    cmd = pytest_cmd(tests, deselect)
    if not stop_first:
        cmd.remove("-x")
    t0 = time.perf_counter()
    try:
        out = subprocess.run(cmd, cwd=copy_root, env=env_for(copy_root), capture_output=True, text=True, timeout=timeout)
    except subprocess.TimeoutExpired:
        return "timeout", time.perf_counter() - t0, ""
    dt = time.perf_counter() - t0
    failed = re.findall(r"^(?:FAILED|ERROR) (\S+)", out.stdout, re.M)
    if out.returncode == 0:
        return "survived", dt, ""
    if failed:
        return "killed", dt, "\n".join(failed)
    tail = out.stdout.strip().splitlines()[-1:] or out.stderr.strip().splitlines()[-1:] or [""]
    return "killed", dt, f"pytest exit {out.returncode}: {tail[0][:200]}"


def baseline(copy_root: Path, tests: list[str]) -> tuple[list[str], float]:
    """Test ids failing on the unmutated copy (deselected afterwards), and the run time."""
    status, dt, failed = run_tests(copy_root, tests, [], timeout=3600, stop_first=False)
    bad = [f for f in failed.splitlines() if "::" in f] if status != "survived" else []
    return bad, dt


def run_module(module: str, muts: list[Mutant], sources: dict[int, bytes], workers: list[Path], timeout_factor: float,
               log) -> dict:
    tests = [t for t in TESTS[module] if (ROOT / t).exists()]
    rel = module_path(module)
    bad, t_base = baseline(workers[0], tests)
    log(f"[{module}] baseline {t_base:.0f} s on {len(tests)} test files; {len(bad)} failing before mutation (deselected)")
    # a survivor runs every test file; on a shared machine its time varies 2-4x from the baseline's
    timeout = max(300.0, timeout_factor * t_base)
    original = (workers[0] / rel).read_bytes()  # the copy's own text (the tree may change meanwhile)
    free = list(workers)

    def one(m: Mutant) -> Mutant:
        w = free.pop()
        try:
            (w / rel).write_bytes(sources[m.index])
            m.status, m.seconds, m.killed_by = run_tests(w, tests, bad, timeout)
        finally:
            (w / rel).write_bytes(original)
            free.append(w)
        log(f"  [{module} #{m.index}, {len(muts)} in this run] {m.status:8s} {m.seconds:5.0f} s  {m.kind}: {m.diff}")
        return m

    with ThreadPoolExecutor(len(workers)) as pool:
        done = list(pool.map(one, muts))
    return {"module": module, "tests": tests, "baseline_failing": bad, "baseline_seconds": t_base,
            "timeout_seconds": timeout, "mutants": [asdict(m) for m in done], "date": time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime())}


# -- report -----------------------------------------------------------------------------------------


def load_notes() -> dict[tuple[str, str], str]:
    """NOTES with their "L<line> " prefixes removed: a note follows its expression when lines move."""
    return {(mod, re.sub(r"^L\d+ ", "", key)): note for (mod, key), note in NOTES.items()}


def load_state(md: Path, legacy: Path) -> dict:
    """Every module's latest results: kept in the report itself (a comment block at its end), so
    that a run on other modules merges into it."""
    if md.exists():
        text = md.read_text()
        if STATE_BEGIN in text:
            return json.loads(text.split(STATE_BEGIN, 1)[1].split(STATE_END, 1)[0])
    if legacy.exists():  # results of a run of an earlier version of this script
        return json.loads(legacy.read_text())
    return {}


def write_report(results: dict, md: Path) -> None:
    notes = load_notes()
    rows, surv = [], []
    tot_k = tot_n = 0
    for mod in sorted(results):
        r = results[mod]
        if not r["mutants"]:
            continue
        ms = [Mutant(**m) for m in r["mutants"]]
        k = sum(m.status == "killed" for m in ms)
        t = sum(m.status == "timeout" for m in ms)
        s = [m for m in ms if m.status == "survived"]
        n = len(ms)
        tot_k += k + t
        tot_n += n
        rate = f"{100 * (k + t) / n:.0f} %" if n else "–"
        rows.append(f"| `{mod}` | {n} | {k} | {t} | {len(s)} | {rate} | {len(r['baseline_failing'])} | {r['date']} |")
        for m in s:
            keys = (f"{m.function}() {m.original}  →  {m.mutated}", f"{m.original}  →  {m.mutated}", f"{m.function}() {m.original}",
                    m.original)
            note = next((notes[(mod, k)] for k in keys if (mod, k) in notes), "(not yet reviewed)")
            surv.append((mod, m, note))
    open_ = [(mod, m, note) for mod, m, note in surv if note.startswith(("NOT KILLED", "(not yet reviewed)"))]
    lines = [
        "# Mutation testing",
        "",
        "Generated by `pipelines/mutation.py` (merged per module; the state is the comment at the end). Each mutant",
        "changes one physical number or operation in one function of the package (numeric constant ×1.01",
        "or ±1, + ↔ −, * ↔ /, exponent +1, comparison flipped, term dropped, unary minus dropped, degree",
        "→ radian conversion dropped, two arguments swapped) and runs the module's test files",
        "(`TESTS` in the script) with `pytest -x` in a copy of the repository. Timeouts count as killed.",
        "Tests failing before mutation (work in progress elsewhere) are deselected and counted in the",
        "last column.",
        "",
        "| module | mutants | killed | timeout | survived | kill rate | failing before | run |",
        "|---|---|---|---|---|---|---|---|",
        *rows,
        f"| **all** | {tot_n} | | | {len(surv)} | **{100 * tot_k / max(tot_n, 1):.0f} %** | | |",
        "",
        f"Survivors: {len(surv)}, of which {len(surv) - len(open_)} explained below (equivalent, an argument check, or "
        f"accuracy only, measured) and {len(open_)} open (" + (", ".join(f"`{mod}` {m.function}()" for mod, m, _ in open_) or "none")
        + ").",
        "",
        *HISTORY,
        "",
        "Mutants are a deterministic sample (`--max-per-module`, `--seed`) of every candidate in the",
        "module (12 for the core physics and the renderer's table, texture and glint, 8 elsewhere in the",
        "last full pass). `tests/test_golden.py` is not in any module's tests: it compares renders bit for",
        "bit with saved renders of this same code, so it fails on any change, checked physics or not.",
        "Swapping the arguments of a symmetric function (`maximum`, `minimum`) is generated too and always",
        "survives (listed as equivalent). Re-run, e.g. after a rewrite:",
        "",
        "    python pipelines/mutation.py --modules renderer --max-per-module 8 --workers 1",
        "    python pipelines/mutation.py --modules expectation --max-per-module 12 --only-survivors",
        "",
        "Not mutated: " + "; ".join(f"`{m}` ({why})" for m, why in NOT_MUTATED.items()) + ".",
        "No candidate (no arithmetic outside argument checks): "
        + ", ".join(f"`{m}`" for m in sorted(TESTS) if m in results and not results[m]["mutants"]) + ".",
        "Not run yet: " + (", ".join(f"`{m}`" for m in sorted(TESTS) if m not in results) or "none") + ".",
        "",
        "## Survivors",
        "",
    ]
    if not surv:
        lines.append("None.")
    for mod in sorted({mod for mod, _, _ in surv}):
        lines += [f"### `{mod}`", ""]
        lines += [f"- {m.function}() {m.kind}: `{m.diff}` — {note}" for md, m, note in surv if md == mod]
        lines.append("")
    # the state: one line a module (the readable report above stays short)
    state = "{\n" + ",\n".join(f"{json.dumps(k)}: {json.dumps(v, ensure_ascii=False)}" for k, v in sorted(results.items())) + "\n}"
    lines += ["", STATE_BEGIN, state, STATE_END]
    md.write_text("\n".join(lines) + "\n")


# -- main -------------------------------------------------------------------------------------------


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--modules", nargs="+", required=True, help=f"modules under {PKG}/ (e.g. slopes reference/planck; 'reference' = all four reference files)")
    ap.add_argument("--max-per-module", type=int, default=25, help="mutants sampled per module (deterministic, --seed)")
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--timeout-factor", type=float, default=4.0, help="timeout per mutant = factor × baseline run time (≥ 300 s)")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--only-survivors", action="store_true", help="re-run only the survivors (and timeouts) recorded in the report (same --max-per-module and --seed)")
    ap.add_argument("--match", help="run only the mutants whose 'function() original → mutated' matches this regular expression")
    ap.add_argument("--list", action="store_true", help="print the mutants and exit")
    ap.add_argument("--report-only", action="store_true", help="rewrite the report from its recorded state and exit")
    ap.add_argument("--json", type=Path, default=ROOT / "docs" / "mutation.json", help=argparse.SUPPRESS)  # legacy state file
    ap.add_argument("--report", type=Path, default=ROOT / "docs" / "mutation.md")
    args = ap.parse_args(argv)

    modules = []
    for m in args.modules:
        m = m.removeprefix(f"{PKG}/").removesuffix(".py")
        modules += MODULE_ALIASES.get(m, [m])
    for m in modules:
        if m not in TESTS or not (ROOT / module_path(m)).exists():
            ap.error(f"unknown module {m!r}; known: {', '.join(sorted(TESTS))}")

    missing = unmapped()
    if missing:
        ap.error(f"modules of {PKG}/ in neither TESTS nor NOT_MUTATED: {', '.join(missing)}")
    gone = missing_test_files()
    if gone:
        ap.error(f"test files in TESTS that do not exist: {', '.join(gone)}")
    results = load_state(args.report, args.json)
    for m in [m for m in results if m not in TESTS or not (ROOT / module_path(m)).exists()]:
        del results[m]  # a module that no longer exists (e.g. render, _pixels before the renderer package)

    def make_plan(root: Path) -> dict:
        # with --only-survivors every candidate is generated, then restricted to the recorded survivors
        # (a module edited since its run samples differently: its survivors are found all the same)
        n_max = 10**9 if args.only_survivors else args.max_per_module
        plan = {m: mutants_of(m, n_max, args.seed, root) for m in modules}
        if args.only_survivors:
            for m, (muts, src) in plan.items():
                # matched by function and text, not line: the file may have moved since
                # (the same text at several lines of a function: the one nearest the recorded line)
                keep = set()
                for x in results.get(m, {}).get("mutants", []):
                    if x["status"] in ("survived", "timeout"):
                        same = [y for y in muts if (y.function, y.original, y.mutated) == (x["function"], x["original"], x["mutated"])]
                        if same:
                            keep.add(min(same, key=lambda y: abs(y.line - x["line"])).index)
                plan[m] = ([x for x in muts if x.index in keep], src)
        if args.match:  # e.g. the survivors a new test is meant to kill
            rx = re.compile(args.match)
            for m, (muts, src) in plan.items():
                plan[m] = ([x for x in muts if rx.search(f"{x.function}() {x.original} → {x.mutated}")], src)
        return plan

    if args.report_only:
        write_report(results, args.report)
        return 0
    if args.list:
        for m, (muts, _) in make_plan(ROOT).items():
            for x in muts:
                print(f"{m:22s} {x.function:28s} {x.kind:20s} {x.diff}")
        return 0

    t0 = time.perf_counter()

    def log(msg: str) -> None:
        print(f"{time.perf_counter() - t0:6.0f} s  {msg}", flush=True)

    with tempfile.TemporaryDirectory(prefix="roughsea_mutation_") as tmp:
        workers = [copy_tree(Path(tmp) / f"w{i}") for i in range(args.workers)]
        for w in workers:
            check_import(w)
        log(f"{len(workers)} copies of the repository in {tmp}; the copy's package is the one imported")
        plan = make_plan(workers[0])  # mutants of the copied text: the tree may change meanwhile
        for m, (muts, src) in plan.items():
            if not muts:
                if not args.only_survivors:
                    results[m] = {"module": m, "tests": TESTS[m], "baseline_failing": [], "baseline_seconds": 0.0,
                                  "timeout_seconds": 0.0, "mutants": [], "date": time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime())}
                continue
            res = run_module(m, muts, src, workers, args.timeout_factor, log)
            if args.only_survivors and m in results:  # update the re-run mutants in place
                new = {(x["function"], x["original"], x["mutated"]): x for x in res["mutants"]}
                res["mutants"] = [new.get((x["function"], x["original"], x["mutated"]), x) for x in results[m]["mutants"]]
            results[m] = res
            write_report(results, args.report)
    write_report(results, args.report)
    log(f"done; report in {args.report}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
