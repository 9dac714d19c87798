"""The spread of a record's observables between packings, as a function of the parameters.

On disordered packings the observables of one parameter set differ from packing to packing,
and a measured record is one packing: its likelihood holds that spread Σ_K(u) besides its
noise (:mod:`~hexdem.calibration.inference`). Σ_K depends on the parameters: it vanishes with
the disorder, grows with σ, and changes with the striker speed or the dissipation. On packings
prepared as the paper's (:mod:`~hexdem.disorder.preparation`) it grows within the compaction's
overlaps (a few 0.1 µm) and is as large at 5 µm as at 140 µm: which neighbours touch is then set
by the signs of the diameters' deviations. It is modelled as

    Σ_K(u) = diag s(u) · R · diag s(u),

with s_j(u) the standard deviation of observable j between packings, emulated on its logarithm
(:class:`~hexdem.calibration.emulator.Emulator`, a linear trend and a process that may be nearly
all nugget: the sets share their packings, so what varies between them is small) from each
parameter set's robust standard deviation over its K packings whose pulse the sensors detect
(:func:`robust_sd`), and R the correlation between the observables (a slow packing's arrivals are
late at every later sensor together), pooled over the parameter sets from the deviations from
their mean scaled by the emulated s, with the records' own scatter where there are several
records (each an independent packing: R − 1 more directions than the K packings' K − 1), and
shrunk towards the identity only as far as those directions fall short of the observables
(:func:`shrunk_correlation`).

**A pulse takes one of a few paths.** Across packings a sensor's relative arrival is not a
Gaussian scatter but a few groups: the pulse reaches the sensor by one path or another, hundreds of
µs apart. So s is a robust scale, that of the main path, and each record's packing deviates as a
Student-t of :data:`RECORD_TAIL_DOF` degrees of freedom about it (:meth:`Spread.record_scale`):
a record whose pulse took another path costs the same few nats at every parameter, rather than
pulling the parameters to where an emulated spread swollen by the other path is widest.

**σ levels from the prior's lower bound.** At σ = 0 every packing is the ideal lattice, and the
spread is zero; past a few 0.1 µm (the compaction's overlaps) which neighbours touch is set by the
deviates' signs, and neither the packings' centre nor their spread moves with σ beyond the
sampling error of K packings (on the paper's hexagon: the relative arrivals 144, 298, 459 µs at
σ = 0, then 169-174, 373-463, 562-604 µs at every level from 13 to 120 µm, without a trend). A
jump that sits within a few 0.1 µm of 0 cannot be emulated by a response smooth in σ, which would
spread it over the whole prior and read an offset of the records' own packings as σ. So sets whose
packings all agree (σ = 0) tell neither centre nor spread, and along σ both emulators are held at
the lowest and highest σ simulated with packings that differ (:func:`disordered_range`), never
extrapolated: below the lowest disordered level the model is that level's, not a trend run down
to the ideal lattice. And every set at one level strikes the same K packings: the emulators take
what those packings share as an effect common to the level (:func:`level_groups`), so that the
32 sets a refinement puts at one level count as one draw of its packings, not 32 (which had the
centre's emulator claim 0.5 µs where the K packings know it to 10).

**What K packings cannot tell.** Every parameter set is simulated on the same K packings, so the
robust scales share one error: their scale is known from K − 1 degrees of freedom only, to some
25 % at K = 8, the same for every σ. The likelihood therefore takes Σ_K,true = λ Σ_K with λ
unknown, inverse-gamma, centred on 1 (:func:`variance_ratio`, :meth:`Spread.scale`), sampled with
the parameters (:mod:`~hexdem.calibration.inference`): the records, independent packings, tell λ
further. One packing per set (the ideal lattice) has no spread.
"""

from __future__ import annotations

import numpy as np

from hexdem.calibration.emulator import Emulator

#: The emulator's nugget bound for what the K shared packings' sampling error makes jump from one
#: parameter set to another: s's (its error common to every set the scale λ takes), and along σ the
#: mean's too (:func:`~hexdem.calibration.inference.fit_stage`).
NOISY_NUGGET = 10.0
#: The degrees of freedom of a record's deviation between packings (:meth:`Spread.record_scale`): a
#: tail heavy enough for a packing whose pulse takes a weak path (a deviation of 15 standard deviations
#: costs 10 in log density where a Gaussian's costs 112), with a finite variance.
RECORD_TAIL_DOF = 4
#: The variance of the median of K normal values over that of one, times K (2/π is its efficiency):
#: the error of the K packings' centre, common to every record, Σ_K · MEDIAN_VARIANCE / K.
MEDIAN_VARIANCE = np.pi / 2
#: An observable's spread is emulated on its logarithm, each set's floored at this share of the sets'
#: median: a set of two or three detected packings that share an observable exactly would otherwise
#: stand 7 below the others' logarithm and drag the emulator with it.
LOG_SD_FLOOR = 0.1
#: Standard deviations between packings are floored here (observables are of order one): a
#: parameter set whose packings agree exactly (σ = 0) keeps a spread of full rank.
SD_FLOOR = 1e-9


#: Croux & Rousseeuw (1992)'s small-sample factors b_n that make 1.4826 b_n MAD of n normal values
#: unbiased for their standard deviation, n = 2 … 9; past 9, n / (n − 0.8).
MAD_SMALL_SAMPLE = {2: 1.196, 3: 1.495, 4: 1.363, 5: 1.206, 6: 1.200, 7: 1.140, 8: 1.129, 9: 1.107}
#: The median absolute deviation's consistency factor at the normal law, 1/Φ⁻¹(3/4).
MAD_NORMAL = 1.4826


def robust_sd(values, valid) -> np.ndarray:
    """The robust standard deviation between packings (n, m) of ``values`` (n, K, m) over the packings
    ``valid`` (n, K): 1.4826 b_k × the median absolute deviation from the median of each set's k
    valid packings (:data:`MAD_SMALL_SAMPLE`), unbiased at the normal law for any k ≥ 2. A packing
    whose pulse took another path moves it by at most one rank, where it swells a sample standard
    deviation past the spread of all the others (132-193 µs against 12-36 µs on the paper's hexagon).
    Where more than half the packings agree exactly (on the paper's hexagon at σ ≤ 24 µm, the pulse
    reaches the second sensor of the 0° line by the same contacts in 5 of 8), the median absolute
    deviation is 0 though the others differ: there it is √(π k / (2 (k − 1))) × the mean absolute
    deviation from the median (a spread of 0 made every record that differs impossible: a log
    likelihood of −72,000). Zero for a set with fewer than two valid packings, or whose packings
    all agree (σ = 0)."""
    counts = valid.sum(axis=1)
    scale = np.zeros((len(counts), np.shape(values)[-1]))
    some = counts >= 2
    values = np.where(valid[some][..., None], np.asarray(values, float)[some], np.nan)
    deviation = np.abs(values - np.nanmedian(values, axis=1, keepdims=True))
    k = counts[some][:, None]
    factors = np.array([MAD_SMALL_SAMPLE.get(int(count), count / (count - 0.8)) for count in counts[some]])
    median_absolute = MAD_NORMAL * factors[:, None] * np.nanmedian(deviation, axis=1)
    mean_absolute = np.sqrt(np.pi / 2 * k / (k - 1)) * np.nanmean(deviation, axis=1)
    scale[some] = np.where(median_absolute > 0, median_absolute, mean_absolute)
    return scale


def packing_centres(observables) -> np.ndarray:
    """Each parameter set's centre (n, m) over its packings whose pulse the sensors detect
    (``observables`` (n, K, m), NaN where not): the median, the main path's, which one packing that
    took another path moves by at most one rank where it moves the mean by 1/K of the paths'
    difference (40 µs between two σ levels of the paper's hexagon); one packing's own observables."""
    return np.nanmedian(observables, axis=1)


def disordered_range(points, sd, smooth) -> tuple[np.ndarray, np.ndarray] | None:
    """(lowest (p,), highest (p,)) of the unit-cube ``points`` (n, p) whose packings differ (robust
    ``sd`` (n, m) above 0 somewhere) along the ``smooth`` dimensions (σ's), unbounded along the
    others: where the emulators of the packings' centre and spread are held (see the module
    docstring; :attr:`Spread.held`); None where no dimension is smooth or no set's packings differ."""
    differ = np.any(np.asarray(sd) > 0, axis=1)
    if not smooth or not differ.any():
        return None
    lowest, highest = np.full(points.shape[1], -np.inf), np.full(points.shape[1], np.inf)
    for j in smooth:
        lowest[j], highest[j] = points[differ, j].min(), points[differ, j].max()
    return lowest, highest


def ideal_sets(observables) -> np.ndarray:
    """Which parameter sets (n,) of ``observables`` (n, K, m) (NaN where a packing's pulse was not
    detected) have two or more detected packings that all agree exactly: the ideal lattice, σ = 0,
    which tells neither the packings' centre nor their spread along σ (see the module docstring)."""
    valid = np.isfinite(np.asarray(observables, float)[..., 0])
    return (valid.sum(axis=1) >= 2) & ~np.any(robust_sd(observables, valid) > 0, axis=1)


def level_groups(points, smooth) -> np.ndarray | None:
    """Labels (n,) of the unit-cube ``points`` (n, p) that share their values along the ``smooth``
    dimensions (σ's: a σ level, whose K packings every set at it strikes), for the emulators' group
    effect (:class:`~hexdem.calibration.emulator.Emulator`); None without such dimensions."""
    if not smooth:
        return None
    return np.unique(np.asarray(points)[:, list(smooth)], axis=0, return_inverse=True)[1].ravel()


def variance_ratio(unit, dof: float) -> np.ndarray:
    """The quantiles ``unit`` of the true variance over one estimated from ν = ``dof`` degrees of
    freedom: ν/X, X of the χ² law of ν degrees of freedom, is inverse-gamma with shape ν/2; its scale
    is set so that the ratio is centred on 1, its mean 1 where it has one (ν > 2: scale (ν − 2)/2) and
    its median 1 where it has none. A scale ν/2 centres the mean on ν/(ν − 2): 2 for ν = 4, 1.4 for
    ν = 7, inflating every spread by as much before the records say a word."""
    from scipy.stats import invgamma

    half = dof / 2
    scale = half - 1 if dof > 2 else 1 / invgamma.median(half)
    return invgamma.ppf(np.clip(np.asarray(unit, float), 1e-12, 1 - 1e-12), half, scale=scale)


def shrunk_correlation(sample, dof: int) -> np.ndarray:
    """The correlation between observables from ``sample``, the correlation of ``dof`` = ν
    independent deviations, shrunk towards the identity: (ν R̂ + w I) / (ν + w), w = max(m + 1 − ν, 1).

    Every parameter set is simulated on the same K packings (:mod:`~hexdem.calibration.packings`),
    so their deviations from the mean, however many sets are pooled, are K − 1 independent vectors
    (and the records R − 1 more): for ν < m observables R̂ is singular, and a record whose packing
    deviates in a direction the packings never took would count as impossible. The estimate is
    that of an inverse-Wishart prior centred on the identity, updated with the ν deviations, and
    worth as many packings as ν falls short of m + 1 (at least one): it stays positive definite.
    A prior worth m + 1 packings whatever ν is would flatten correlations the data hold (0.9 read
    as 0.42 at ν = 7, m = 7), and widen the spread across the common direction where the
    packings deviate least: a record's σ then came out low (docs/validation/benchmarks.md)."""
    size = len(sample)
    weight = max(size + 1 - dof, 1)
    return (dof * np.asarray(sample, float) + weight * np.eye(size)) / (dof + weight)


def records_correlation(scatter) -> np.ndarray:
    """The correlation of the packings' deviations that the records' own ``scatter`` shows (their
    covariance less what their noise and the striker's speed add, (m, m)), its eigenvalues floored
    at a thousandth of the largest so that it is one."""
    values, vectors = np.linalg.eigh(np.asarray(scatter, float))
    values = np.maximum(values, 1e-3 * max(values.max(), SD_FLOOR**2))
    covariance = (vectors * values) @ vectors.T
    norm = np.sqrt(np.diag(covariance))
    return covariance / np.outer(norm, norm)


class Spread:
    """Σ_K(u) fitted to simulations at unit-cube ``points`` (n, p) with ``observables`` (n, K, m), NaN
    for a packing whose pulse the sensors do not detect (left out; a set with fewer than two
    detected packings tells no spread);
    with ``scatter``, the records' own covariance between packings (:func:`records_correlation`)
    from ``scatter_dof`` independent records' deviations, pooled into the correlation: records of
    independent packings are more independent directions than the K packings' K − 1; ``smooth``,
    the dimensions along which s is smooth over the whole prior
    (:class:`~hexdem.calibration.emulator.Emulator`)."""

    def __init__(self, points, observables, scatter=None, scatter_dof: int = 0, smooth=()):
        observables = np.asarray(observables, float)
        n, self.realizations, self.size = observables.shape
        self.held = None
        if self.realizations < 2:
            return
        valid = np.isfinite(observables[..., 0])
        counts = valid.sum(axis=1)
        usable = counts >= 2
        points, observables, valid, counts = points[usable], observables[usable], valid[usable], counts[usable]
        mean = np.nanmean(observables, axis=1, keepdims=True)
        centred = np.where(valid[..., None], observables - mean, 0.0)
        sd = robust_sd(observables, valid)
        spread = np.any(sd > 0, axis=1)
        self.held = disordered_range(points, sd, smooth)
        floor = np.maximum(LOG_SD_FLOOR * np.median(sd[spread], axis=0), SD_FLOOR)
        self.sd = Emulator(
            points[spread],
            np.log(np.maximum(sd[spread], floor)),
            nugget_max=NOISY_NUGGET,
            smooth=smooth,
            held=self.held,
            groups=level_groups(points[spread], smooth),
        )
        self.dof = int(np.median(counts)) - 1
        scaled = centred / self._sd(points)[:, None, :]
        pooled = np.einsum("nki,nkj->ij", scaled, scaled)
        norm = np.sqrt(np.diag(pooled))
        simulated, dof = pooled / np.outer(norm, norm), self.dof
        if scatter is not None and scatter_dof > 0:
            simulated = (dof * simulated + scatter_dof * records_correlation(scatter)) / (dof + scatter_dof)
            dof += scatter_dof
        self.correlation = shrunk_correlation(simulated, dof)

    def __call__(self, unit) -> np.ndarray:
        """Σ_K (k, m, m) at unit-cube points ``unit`` (k, p)."""
        unit = np.atleast_2d(unit)
        if self.realizations < 2:
            return np.zeros((len(unit), self.size, self.size))
        sd = self._sd(unit)
        return sd[:, :, None] * self.correlation * sd[:, None, :]

    def scale(self, unit) -> np.ndarray:
        """The spread's scale λ (Σ_K,true = λ Σ_K) at unit coordinates ``unit`` (k,): the K packings'
        scales, shared by every parameter set, carry K − 1 degrees of freedom (the median set's
        detected packings less one): :func:`variance_ratio` of K − 1, centred on 1."""
        return variance_ratio(unit, self.dof)

    def record_scale(self, unit) -> np.ndarray:
        """Each record's packing scale λ_r (its deviation ~ N(0, λ_r Σ_K)) at unit coordinates ``unit``:
        :func:`variance_ratio` of ν = :data:`RECORD_TAIL_DOF`, inverse-gamma with mean 1, so that a
        record's deviation is a Student-t of ν degrees of freedom whose variance is Σ_K."""
        return variance_ratio(unit, RECORD_TAIL_DOF)

    def _sd(self, unit) -> np.ndarray:
        """s (k, m) at ``unit`` (k, p): the exponential of its logarithm's emulator, which stays positive
        where an emulator of s itself ran below zero between sets of small and large spread."""
        return np.maximum(np.exp(self.sd.predict(unit)[0]), SD_FLOOR)
