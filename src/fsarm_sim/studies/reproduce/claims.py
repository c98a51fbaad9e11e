"""Claims of the seed papers and the rules that judge our simulator against them.

A :class:`Claim` is *data*, written from a paper's text, table or figure caption before any of our
numbers is looked at: the paper, where in it (section/table/figure/equation), a short quote, the
paper's value (or the trend it states) with its unit, and the tolerance - the rule that turns our
measured value into a verdict. How *ours* is measured is a separate function (the ``measure``
name, looked up in the paper's ``measureNNN`` module); a claim that cannot be run yet says why
(``not_implemented``), one whose paper text cannot be read without guessing says why
(``uncheckable``).

Verdicts (:data:`VERDICTS`):

* ``reproduced``   - ours satisfies the tolerance;
* ``partly``       - ours misses it but lies within the tolerance's wider ``partly`` band (a trend
  that points the right way but is not monotone or too small, a value within the wider band);
* ``contradicted`` - outside both;
* ``not_implemented`` - the experiment cannot be run on the simulator yet (the why says what is
  missing);
* ``uncheckable``  - the paper's statement cannot be checked without guessing (garbled text,
  figures only, the text contradicting its own table).

Roles (:data:`ROLES`): every claim says what it is to the model, so that fitting and checking stay
apart (issue 27):

* ``prediction``   - nothing in the model was chosen from it: the only evidence of fidelity
  (a prediction written after ours was seen says so in ``post_hoc`` and is counted apart, never
  as evidence);
* ``calibration``  - a parameter was chosen or fitted from it (``calibrates`` names which); its
  verdict says the calibration holds, not that the model predicts it;
* ``consistency``  - a number transcribed into the model, a formula checked against itself, a
  structural identity: a check of the code against the paper, never counted as reproduced.

``role_why`` says why a claim has its role (which parameter, which transcription).

Tolerance kinds (each has :meth:`judge` and :meth:`text`): :class:`Rel`, :class:`Abs`,
:class:`Factor` (numbers), :class:`Between` (a published range), :class:`AtLeast`,
:class:`AtMost` (inequalities), :class:`Trend` (a direction over ordered conditions, with
monotonicity), :class:`AllOf` (a list of named conditions) and :class:`Ranking` (an order).
"""

from __future__ import annotations

import itertools
import math
import operator
from collections.abc import Callable, Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any, Literal, TypeVar

T = TypeVar("T")
Role = Literal["prediction", "calibration", "consistency"]
ROLES: tuple[Role, ...] = ("prediction", "calibration", "consistency")
Verdict = Literal["reproduced", "partly", "contradicted", "not_implemented", "uncheckable"]
VERDICTS: tuple[Verdict, ...] = (
    "reproduced",
    "partly",
    "contradicted",
    "not_implemented",
    "uncheckable",
)
PAPERS: dict[str, str] = {
    "000": "Usman et al., Flexible shaft as remote and elastic transmission (seed 000)",
    "001": "Rodriguez-Cianca et al., RTCA, Mechatronics 2019 (seed 001)",
    "002": "Eiberger et al., DLR QA-Joint (seed 002)",
    "003": "Magnetic-spring VSA ATTRACTOR (seed 003)",
    "004": "Compliant control of single tendon-sheath actuators (seed 004)",
}


class ClaimError(ValueError):
    """A claim declaration or a measurement that does not fit its tolerance kind."""


_RANK = {"contradicted": 0, "partly": 1, "reproduced": 2}


def worst(verdicts: Iterable[Verdict]) -> Verdict:
    """The weakest of judged verdicts (contradicted < partly < reproduced)."""
    return min(verdicts, key=lambda v: _RANK[v])


def _finite(x: Any) -> bool:
    return isinstance(x, int | float) and not isinstance(x, bool) and math.isfinite(x)


def _number(x: Any, what: str) -> float:
    if not _finite(x):
        raise ClaimError(f"{what} must be a finite number, got {x!r}")
    return float(x)


def _fmt(x: float) -> str:
    return f"{x:.4g}"


def _graded(
    x: float, limit: float, partly: float | None, within: Callable[[float, float], bool]
) -> Verdict:
    """reproduced where ``within(x, limit)``, partly where ``within(x, partly)``, else contradicted."""
    if within(x, limit):
        return "reproduced"
    if partly is not None and within(x, partly):
        return "partly"
    return "contradicted"


def _unit(unit: str) -> str:
    return f" {unit}" if unit and unit != "-" else ""


def _partly_text(partly: float | None, prefix: str, suffix: str = "") -> str:
    """`` (partly <prefix><partly><suffix>)``, or nothing where there is no partly band."""
    return f" (partly {prefix}{partly:g}{suffix})" if partly is not None else ""


# ----------------------------------------------------------------------------------------------
# tolerance kinds


@dataclass(frozen=True)
class Rel:
    """|ours - paper| <= tol * |paper| -> reproduced; <= partly * |paper| -> partly."""

    tol: float
    partly: float | None = None
    needs_paper_value = True

    def judge(self, paper: float | None, ours: Any) -> Verdict:
        p = _number(paper, "paper value")
        o = _number(ours, "ours")
        err = abs(o - p) / abs(p) if p != 0.0 else abs(o)
        return _graded(err, self.tol, self.partly, operator.le)

    def text(self, unit: str) -> str:
        partly = None if self.partly is None else 100 * self.partly
        return f"±{100 * self.tol:g} %" + _partly_text(partly, "±", " %")


@dataclass(frozen=True)
class Abs:
    """|ours - paper| <= tol -> reproduced; <= partly -> partly (in the claim's unit)."""

    tol: float
    partly: float | None = None
    needs_paper_value = True

    def judge(self, paper: float | None, ours: Any) -> Verdict:
        err = abs(_number(ours, "ours") - _number(paper, "paper value"))
        return _graded(err, self.tol, self.partly, operator.le)

    def text(self, unit: str) -> str:
        u = _unit(unit)
        return f"±{self.tol:g}{u}" + _partly_text(self.partly, "±", u)


@dataclass(frozen=True)
class Factor:
    """paper / f <= ours <= paper * f -> reproduced (order of magnitude; paper > 0)."""

    factor: float
    partly: float | None = None
    needs_paper_value = True

    def judge(self, paper: float | None, ours: Any) -> Verdict:
        p = _number(paper, "paper value")
        o = _number(ours, "ours")
        if p <= 0.0:
            raise ClaimError("a Factor tolerance needs a positive paper value")
        if o <= 0.0:
            return "contradicted"
        return _graded(max(o / p, p / o), self.factor, self.partly, operator.le)

    def text(self, unit: str) -> str:
        return f"within ×{self.factor:g}" + _partly_text(self.partly, "×")


@dataclass(frozen=True)
class Between:
    """Every value of ours within [lo, hi] -> reproduced; within [lo/f, hi*f] -> partly."""

    lo: float
    hi: float
    partly_factor: float | None = None
    needs_paper_value = False

    def judge(self, paper: float | None, ours: Any) -> Verdict:
        values = [_number(v, "ours") for v in (ours if isinstance(ours, Sequence) else [ours])]
        if not values:
            raise ClaimError("Between needs at least one value")
        if all(self.lo <= v <= self.hi for v in values):
            return "reproduced"
        f = self.partly_factor
        if f is not None and all(self.lo / f <= v <= self.hi * f for v in values):
            return "partly"
        return "contradicted"

    def text(self, unit: str) -> str:
        s = f"all in [{self.lo:g}, {self.hi:g}]{_unit(unit)}"
        if self.partly_factor is not None:
            s += f" (partly within ×{self.partly_factor:g})"
        return s


@dataclass(frozen=True)
class AtLeast:
    """ours >= threshold -> reproduced; >= partly -> partly."""

    threshold: float
    partly: float | None = None
    needs_paper_value = False

    def judge(self, paper: float | None, ours: Any) -> Verdict:
        return _graded(_number(ours, "ours"), self.threshold, self.partly, operator.ge)

    def text(self, unit: str) -> str:
        return f"≥ {self.threshold:g}{_unit(unit)}" + _partly_text(self.partly, "≥ ")


@dataclass(frozen=True)
class AtMost:
    """ours <= threshold -> reproduced; <= partly -> partly."""

    threshold: float
    partly: float | None = None
    needs_paper_value = False

    def judge(self, paper: float | None, ours: Any) -> Verdict:
        return _graded(_number(ours, "ours"), self.threshold, self.partly, operator.le)

    def text(self, unit: str) -> str:
        return f"≤ {self.threshold:g}{_unit(unit)}" + _partly_text(self.partly, "≤ ")


@dataclass(frozen=True)
class Trend:
    """A direction over ordered conditions (ours: the values in the claim's condition order, or
    a mapping name -> such a sequence, each of which must show the trend; the worst one counts).

    * reproduced: every step goes the stated way or stays within ``tie`` (relative to the first
      value's magnitude; ``strict=True`` forbids ties), and the total change from first to last
      goes the stated way by more than ``tie`` and by at least ``min_change`` (relative to the
      first value);
    * partly: the total change goes the stated way by more than ``tie``, but a step goes against
      it or the change is below ``min_change``;
    * contradicted: no change beyond ``tie``, the wrong way, or every value below ``floor`` (in
      the claim's unit: the quantity is absent, so it cannot trend).

    Where the paper states the size of its change, ``paper_change`` carries it (the total
    relative change, first to last, as a positive fraction: a fall 6.22 -> 4.30 Hz is 0.31) and
    the size is judged too: reproduced needs the total within ``change_factor`` of the paper's
    (``paper/f <= total <= paper*f``, and monotone), partly within ``change_factor``² (or the
    size right but not monotone); a change the right way but outside that is contradicted (a
    1 % fall where the paper reports 31 % is not the paper's trend). ``min_change`` is then 0.
    """

    direction: Literal["increasing", "decreasing"]
    min_change: float = 0.0
    tie: float = 0.01
    strict: bool = False
    floor: float = 0.0
    paper_change: float | None = None
    change_factor: float = 2.0
    needs_paper_value = False

    def __post_init__(self) -> None:
        if self.paper_change is not None:
            if not (_finite(self.paper_change) and self.paper_change > 0.0):
                raise ClaimError(
                    f"a Trend's paper_change must be a positive fraction, got {self.paper_change!r}"
                )
            if not (_finite(self.change_factor) and self.change_factor > 1.0):
                raise ClaimError(f"a Trend's change_factor must be > 1, got {self.change_factor!r}")
            if self.min_change:
                raise ClaimError("a Trend takes paper_change or min_change, not both")

    def _one(self, ours: Any) -> Verdict:
        if not isinstance(ours, Sequence) or len(ours) < 2:
            raise ClaimError("a Trend needs at least two values (one per condition)")
        y = [_number(v, "ours") for v in ours]
        if max(abs(v) for v in y) <= self.floor:
            return "contradicted"
        sign = 1.0 if self.direction == "increasing" else -1.0
        scale = max(abs(y[0]), self.floor) or max(abs(v) for v in y)
        steps = [sign * (b - a) / scale for a, b in itertools.pairwise(y)]
        total = sign * (y[-1] - y[0]) / scale
        monotone = (
            all(s > self.tie for s in steps) if self.strict else all(s >= -self.tie for s in steps)
        )
        if self.paper_change is not None:
            if total <= self.tie:
                return "contradicted"
            p, f = self.paper_change, self.change_factor
            if monotone and p / f <= total <= p * f:
                return "reproduced"
            if p / (f * f) <= total <= p * f * f:
                return "partly"
            return "contradicted"
        if monotone and total > self.tie and total >= self.min_change:
            return "reproduced"
        if total > self.tie:
            return "partly"
        return "contradicted"

    def judge(self, paper: float | None, ours: Any) -> Verdict:
        if isinstance(ours, Mapping):
            if not ours:
                raise ClaimError("a Trend mapping needs at least one sequence")
            return worst(self._one(v) for v in ours.values())
        return self._one(ours)

    def text(self, unit: str) -> str:
        word = "rises" if self.direction == "increasing" else "falls"
        s = f"{word} {'strictly ' if self.strict else ''}monotonically"
        if self.paper_change is not None:
            p, f = 100 * self.paper_change, self.change_factor
            s += (
                f", by the paper's {p:.3g} % within ×{f:g} ({p / f:.3g}–{p * f:.3g} %; "
                f"partly {p / f / f:.3g}–{p * f * f:.3g} %)"
            )
        elif self.min_change > 0.0:
            s += f", by ≥ {100 * self.min_change:g} % in total"
        return s + f" (ties ≤ {100 * self.tie:g} %)"


@dataclass(frozen=True)
class AllOf:
    """Named conditions (ours: a sequence of booleans, one per condition, same order).

    All true -> reproduced; at least ``partly_min`` of them (a fraction) -> partly; else
    contradicted.
    """

    conditions: tuple[str, ...]
    partly_min: float = 0.5
    needs_paper_value = False

    def judge(self, paper: float | None, ours: Any) -> Verdict:
        if not isinstance(ours, Sequence) or len(ours) != len(self.conditions):
            raise ClaimError(
                f"AllOf needs one boolean per condition ({len(self.conditions)}), got {ours!r}"
            )
        flags = [bool(v) for v in ours]
        if all(flags):
            return "reproduced"
        if sum(flags) >= self.partly_min * len(flags) and any(flags):
            return "partly"
        return "contradicted"

    def text(self, unit: str) -> str:
        return "all of: " + "; ".join(self.conditions)


@dataclass(frozen=True)
class Ranking:
    """An order, best (smallest) first (ours: label -> value).

    reproduced: each value is below the next by more than ``tie`` (relative); partly: at least
    ``partly_pairs`` of all label pairs are in the stated order beyond ``tie``; else contradicted.
    """

    order: tuple[str, ...]
    tie: float = 0.001
    partly_pairs: float = 0.7
    needs_paper_value = False

    def judge(self, paper: float | None, ours: Any) -> Verdict:
        if not isinstance(ours, Mapping) or set(ours) != set(self.order):
            raise ClaimError(f"Ranking needs a value for each of {self.order}, got {ours!r}")
        v = [_number(ours[k], f"ours[{k}]") for k in self.order]

        def below(a: float, b: float) -> bool:
            return a < b * (1.0 - self.tie)

        if all(below(a, b) for a, b in itertools.pairwise(v)):
            return "reproduced"
        pairs = [(i, j) for i in range(len(v)) for j in range(i + 1, len(v))]
        good = sum(1 for i, j in pairs if below(v[i], v[j]))
        if good >= self.partly_pairs * len(pairs):
            return "partly"
        return "contradicted"

    def text(self, unit: str) -> str:
        return " < ".join(self.order) + f" (each by > {100 * self.tie:g} %)"


Tolerance = Rel | Abs | Factor | Between | AtLeast | AtMost | Trend | AllOf | Ranking


# ----------------------------------------------------------------------------------------------
# claims and measurements


@dataclass(frozen=True)
class Claim:
    """One quantitative claim of a paper (see the module docstring)."""

    id: str
    paper: str  # "000".."004"
    title: str
    locator: str  # section / table / figure / equation
    quote: str  # a short quote or paraphrase of the statement
    paper_text: str  # the paper's value or trend as it is stated, with its unit
    unit: str  # unit of paper_value and ours ("-" when dimensionless)
    tolerance: Tolerance
    paper_value: float | None = None
    measure: str | None = None  # name in the paper's MEASURES
    not_implemented: str | None = None  # why the experiment cannot run yet
    uncheckable: str | None = None  # why the statement cannot be checked
    issue_item: int | None = None  # issue 12's "what the simulator contradicts" item
    quick: bool = True  # part of ``--quick``
    role: str = ""  # one of ROLES (module docstring); required
    calibrates: tuple[str, ...] = ()  # calibration: the parameter(s) chosen/fitted from it
    role_why: str = ""  # why this role: which parameter, transcription or identity
    # a prediction written (or its tolerance chosen) after ours was seen: what was seen. It is
    # reported apart from the blind predictions and never counts as reproduced.
    post_hoc: str = ""

    def __post_init__(self) -> None:
        self.check_role()

    def check_role(self) -> None:
        """The role is declared and fits (a claim without one cannot be built)."""
        if self.role not in ROLES:
            raise ClaimError(
                f"{self.id}: role must be one of {', '.join(ROLES)}, got {self.role!r}"
            )
        if not isinstance(self.calibrates, tuple) or not all(
            isinstance(p, str) and p.strip() for p in self.calibrates
        ):
            raise ClaimError(
                f"{self.id}: calibrates must be a tuple of parameter names, got {self.calibrates!r}"
            )
        if self.role == "calibration" and not self.calibrates:
            raise ClaimError(
                f"{self.id}: a calibration claim must name the parameter(s) chosen from it "
                "(calibrates=...)"
            )
        if self.role != "calibration" and self.calibrates:
            raise ClaimError(
                f"{self.id}: only a calibration claim names calibrated parameters "
                f"(role {self.role!r}, calibrates {self.calibrates!r})"
            )
        if self.post_hoc and self.role != "prediction":
            raise ClaimError(
                f"{self.id}: only a prediction can be marked post_hoc (role {self.role!r})"
            )

    @property
    def counts_as_reproduced(self) -> bool:
        """Only a blind prediction's verdict is evidence (a calibration or consistency claim
        that holds says the model was built from it; a post-hoc prediction was written after
        ours was seen)."""
        return self.role == "prediction" and not self.post_hoc

    def validate(self) -> None:
        self.check_role()
        if self.paper not in PAPERS:
            raise ClaimError(
                f"{self.id}: paper must be one of {sorted(PAPERS)}, got {self.paper!r}"
            )
        if not self.id.startswith(self.paper + "-"):
            raise ClaimError(f"{self.id}: the id must start with the paper, '{self.paper}-'")
        for name in ("title", "locator", "quote", "paper_text", "unit"):
            if not str(getattr(self, name)).strip():
                raise ClaimError(f"{self.id}: '{name}' must not be empty")
        ways = [w for w in (self.measure, self.not_implemented, self.uncheckable) if w]
        if len(ways) != 1:
            raise ClaimError(
                f"{self.id}: exactly one of measure, not_implemented, uncheckable must be given"
            )
        needs = getattr(self.tolerance, "needs_paper_value", False)
        if needs and not _finite(self.paper_value):
            raise ClaimError(f"{self.id}: a {type(self.tolerance).__name__} needs a paper_value")


@dataclass
class Measured:
    """What a measurement function returns.

    ``ours`` is what the tolerance judges (a number, a list of values for a Trend/Between, a list
    of booleans for AllOf, a dict for a Ranking); ``text`` shows it with units; ``details`` holds
    the raw numbers for the JSON report; ``note`` says anything a reader must know (the
    experiment's set-up, an estimate used).
    """

    ours: Any
    text: str
    details: dict[str, Any] = field(default_factory=dict)
    note: str = ""


@dataclass
class Result:
    claim: Claim
    verdict: Verdict
    ours: Any = None
    ours_text: str = ""
    why: str = ""  # not_implemented / uncheckable reason, or a failure
    note: str = ""
    details: dict[str, Any] = field(default_factory=dict)
    seconds: float = 0.0
    failed: bool = False  # the experiment raised (verdict not_implemented, why says what)

    def as_dict(self) -> dict[str, Any]:
        c = self.claim
        return {
            "id": c.id,
            "paper": c.paper,
            "title": c.title,
            "locator": c.locator,
            "quote": c.quote,
            "paper_value": c.paper_value,
            "paper_text": c.paper_text,
            "unit": c.unit,
            "tolerance": c.tolerance.text(c.unit),
            "tolerance_kind": type(c.tolerance).__name__,
            "ours": _jsonable(self.ours),
            "ours_text": self.ours_text,
            "verdict": self.verdict,
            "why": self.why,
            "note": self.note,
            "issue_item": c.issue_item,
            "role": c.role,
            "calibrates": list(c.calibrates),
            "role_why": c.role_why,
            "post_hoc": c.post_hoc,
            "evidence": c.counts_as_reproduced and self.verdict == "reproduced",
            "failed": self.failed,
            "seconds": round(self.seconds, 3),
            "details": _jsonable(self.details),
        }


def _jsonable(x: Any) -> Any:
    """Plain JSON values: floats (NaN/inf as None), lists, dicts with string keys."""
    if isinstance(x, bool) or x is None or isinstance(x, str):
        return x
    if isinstance(x, int | float):
        return float(x) if math.isfinite(x) else None
    if isinstance(x, Mapping):
        return {str(k): _jsonable(v) for k, v in x.items()}
    if hasattr(x, "tolist"):
        return _jsonable(x.tolist())
    if isinstance(x, Sequence | set | frozenset):
        return [_jsonable(v) for v in x]
    if hasattr(x, "item"):
        return _jsonable(x.item())
    return str(x)


def judge(claim: Claim, measured: Measured) -> Verdict:
    """The verdict of a measured claim under its tolerance."""
    return claim.tolerance.judge(claim.paper_value, measured.ours)


@dataclass
class Context:
    """What a measurement function gets: the run's settings and a memo shared by the claims of
    one run (an experiment several claims read is run once per run; nothing is kept between
    runs)."""

    quick: bool = False
    backend: Literal["python", "native"] = "native"
    memo: dict[str, Any] = field(default_factory=dict)

    def once(self, key: str, fn: Callable[[], T]) -> T:
        if key not in self.memo:
            self.memo[key] = fn()
        value: T = self.memo[key]
        return value


MeasureFn = Callable[[Context], Measured]
