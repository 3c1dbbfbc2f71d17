"""Independent numpy/scipy reference implementation of the rough-sea radiance model.

Paper: "A probabilistic model of the apparent radiance of a rough sea" (Eqs. 1, 4-10, A7/A8).
Written in the paper's (theta, phi) facet-normal form and integrated with nested adaptive
scipy quadrature (default epsrel 1e-10; shadow edge, sky/sea edge and density support are put at
integration limits / breakpoints in closed form). About 0.05-1.5 s per evaluation; meant only to
judge the fast implementation. Imports numpy and scipy only. Self-checks:
``python -m roughsea_torch.reference._selfcheck``.

Choices and notes on the paper (see also the docstrings):

* A8's sign of the r term agrees with the bivariate normal of (s_x, s_y) with covariance
  [[a^2, r a b], [r a b, b^2]] (checked pointwise in _selfcheck).
* A4 prints the prefactor as (1/2pi) 2 sigma^2; the normalized density has (1/2pi)(2/sigma^2).
* The paper says the polar integration runs over 0..pi; p is supported on theta in [0, pi/2) and
  that is the range used (p = 0 beyond).
* The paper's symmetry "p(theta, phi) = p(theta, pi - phi)" is a mirror symmetry that fails when
  r != 0; what makes the Eq. 5 denominator equal cos(th) without shadowing is the inversion
  p(theta, phi) = p(theta, phi + pi), which holds for every Gaussian law (checked by quadrature).
* Reflected rays with cos(theta') < 0 see R_B (docs/physics.md sec. 4). Without shadowing (Eq. 7) the
  hidden facets keep negative weight, and near grazing the apparent radiance becomes strongly
  unphysical (e.g. about -1.76e3 at 89.99 deg, W = 10, for R_B = 30): that is what Eq. 7 gives.
* Without shadowing at th = pi/2 exactly, Eq. 7 is 0/0: emissivity and apparent_radiance return NaN.
* An rms slope exactly 0 (one axis) is handled as the degenerate line law (facet normals in one
  vertical plane; corr is then irrelevant). Both 0: flat-sea closed form, no quadrature.
  Very strong anisotropy (a/b > ~1e6) loses accuracy (~1e-8) to the rounding of phi.
* The reflected sun (glint_radiance, module sun): Eq. 10 with R_s = the sun's disk radiance,
  integrated directly over the disk in direction space (half-vector change of variables).
"""

from .fresnel import fresnel_reflectance
from .planck import band_radiance, brightness_temperature, planck_radiance
from .rough_sea import apparent_radiance, emissivity, projected_area
from .slopes import SlopeStatistics, slope_pdf
from .sun import glint_radiance, sun_masking_g1, sun_solid_angle

__all__ = [
    "SlopeStatistics",
    "slope_pdf",
    "fresnel_reflectance",
    "projected_area",
    "emissivity",
    "apparent_radiance",
    "planck_radiance",
    "band_radiance",
    "brightness_temperature",
    "glint_radiance",
    "sun_masking_g1",
    "sun_solid_angle",
]
