"""Bad-input battery for settings that used to be silently ignored or misread (issue 17, item 6).

* Shaft coefficient files (TOML) are strict: unknown sections/keys, wrong types, undeclared or
  wrong units are CoefficientFileErrors naming the file and the key; the file's
  ``series.maxwell_slip.enabled`` takes effect; its ``validity.bend_rad`` bounds arm runs the same
  way it bounds sweeps (one check, ``shaft.check_bend_rad``).
* Every transmission parameter declares its valid range (``Param.bounds``) and is checked at build
  time; the battery below is generated from those declarations, so a new parameter is covered
  without touching this file. Cross-parameter checks (``sigma_min < sigma_max`` ...) per module.

Models are built, not run (each case fails or passes before the first step): the file runs in a
few seconds.
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Callable
from importlib import resources
from pathlib import Path

import numpy as np
import pytest

from fsarm_sim.engine.model import SimConfig, build_model
from fsarm_sim.errors import CoefficientFileError, FsarmError, ShaftRangeError
from fsarm_sim.plant import transmissions
from fsarm_sim.plant.shaft import UNITS, load_catalogue
from fsarm_sim.plant.transmissions.base import Bounds, Param, Transmission, TransmissionError
from fsarm_sim.studies import sweep as sw

from conftest import hold_table, run_fsarm

DEFAULT_TOML = resources.files("fsarm_sim.data").joinpath("shafts.toml").read_text("utf-8")
NAMES = transmissions.names()
HOLD = hold_table(0.0, 0.6, 0.4, n=2)  # q2 = 0.6 rad: inside every bend range used here


def _oneline(text: str) -> str:
    """The console wraps long messages: compare with whitespace collapsed."""
    return " ".join(text.split())


def _write(tmp_path: Path, text: str, name: str = "mine.toml") -> Path:
    f = tmp_path / name
    f.write_text(text, encoding="utf-8")
    return f


def _edit(old: str, new: str) -> Callable[[str], str]:
    def apply(text: str) -> str:
        assert old in text, f"the default catalogue no longer contains {old!r}"
        return text.replace(old, new, 1)

    return apply


def _add(line: str, after: str) -> Callable[[str], str]:
    return _edit(after, f"{after}\n{line}")


# ================================================================== coefficient files (TOML)

# (edit of the default file, words the message must contain besides the file's path)
BAD_FILES: dict[str, tuple[Callable[[str], str], tuple[str, ...]]] = {
    # misspelt sections and keys used to fall back to defaults
    "misspelt section": (
        _edit("[series.maxwell_slip]", "[series.maxwel_slip]"),
        ("series.maxwel_slip", "maxwell_slip"),
    ),
    "misspelt top-level section": (_edit("[rating]", "[ratings]"), ("ratings", "rating")),
    "misspelt key": (
        _edit("stiffness_fraction = [0.8", "stifness_fraction = [0.8"),
        ("stifness_fraction", "series.maxwell_slip", "stiffness_fraction"),
    ),
    "misspelt dynamic key": (
        _edit("damping_pos_nms = 0.0", "damping_pos_nm = 0.0"),
        ("damping_pos_nm", "series.dynamic", "damping_pos_nms"),
    ),
    "unknown validity key": (
        _add("bend_deg = [-120.0, 120.0]", "length_mm = [235.0, 535.0]"),
        ("bend_deg", "validity", "bend_rad"),
    ),
    "unknown key in a shaft entry": (
        _edit('name = "MF05-335"', 'name = "MF05-335"\ndiameter = 5.0'),
        ("diameter", "shafts[1]", "diameter_mm"),
    ),
    "unknown units entry": (
        _edit('units = { diameter = "mm"', 'units = { torque = "N*m", diameter = "mm"'),
        ("torque", "meta.units"),
    ),
    # wrong types: the string "false" switched hysteresis ON
    "string false": (
        _edit("enabled = true", 'enabled = "false"'),
        ("series.maxwell_slip.enabled", "'false'", "boolean"),
    ),
    "string true": (
        _edit("enabled = true", 'enabled = "true"'),
        ("series.maxwell_slip.enabled", "boolean"),
    ),
    "integer flag": (_edit("enabled = true", "enabled = 1"), ("series.maxwell_slip.enabled",)),
    "number as string": (
        _edit("stiffening_per_rad2 = 0.1", 'stiffening_per_rad2 = "0.1"'),
        ("bending.stiffening_per_rad2", "finite number"),
    ),
    "boolean as number": (
        _edit("inertia_kgm2 = 0.0", "inertia_kgm2 = true"),
        ("series.dynamic.inertia_kgm2", "finite number"),
    ),
    "infinite range end": (
        _edit("diameter_mm = [4.0, 13.0]", "diameter_mm = [4.0, inf]"),
        ("validity.diameter_mm", "finite"),
    ),
    "nan coefficient": (
        _edit("p = [1.334, ", "p = [nan, "),
        ("series.positive.p", "finite"),
    ),
    "section given as a value": (
        lambda t: (
            "rating = 0.0105\n" + _edit("[rating]\ncoefficient_nm_per_mm3 = 0.01171875", "")(t)
        ),
        ("'rating'", "table"),
    ),
    "shaft name not a string": (
        _edit('name = "MF04-235"', "name = 4"),
        ("shafts[0].name", "string"),
    ),
    "shaft names repeated": (
        _edit('name = "MF05-335"', 'name = "MF04-235"'),
        ("shafts[1].name", "MF04-235", "twice"),
    ),
    "shaft diameter missing": (
        _edit('name = "MF04-235"\ndiameter_mm = 4.0\n', 'name = "MF04-235"\n'),
        ("shafts[0]", "diameter_mm"),
    ),
    "meta name not a string": (
        _edit('name = "fsarm default catalogue (estimates)"', "name = 3"),
        ("meta.name", "string"),
    ),
    # [meta].units must be the units the coefficients are written in
    "diameter in metres": (
        _edit('diameter = "mm"', 'diameter = "m"'),
        ("meta.units.diameter", "'m'", "'mm'"),
    ),
    "length in metres": (
        _edit('length = "mm"', 'length = "m"'),
        ("meta.units.length", "'mm'"),
    ),
    "bend in degrees": (_edit('bend = "rad"', 'bend = "deg"'), ("meta.units.bend", "'rad'")),
    "stiffness per degree": (
        _edit('stiffness = "N*m/rad"', 'stiffness = "N*m/deg"'),
        ("meta.units.stiffness", "N*m/rad"),
    ),
    "units as a number": (_edit('bend = "rad"', "bend = 1"), ("meta.units.bend",)),
    # Maxwell-slip settings that would have no effect
    "enabled without elements": (
        _edit(
            "enabled = true\nstiffness_fraction = [0.8, 0.4, 0.2]",
            "enabled = true\nstiffness_fraction = [0.0, 0.0, 0.0]",
        ),
        ("series.maxwell_slip.enabled", "stiffness_fraction"),
    ),
    "element without slip torque": (
        _edit(
            "slip_torque_fraction = [0.01756, 0.02634, 0.0439]",
            "slip_torque_fraction = [0.01756, 0.0, 0.0439]",
        ),
        ("element 2", "slip_torque_fraction"),
    ),
    "negative slip fraction": (
        _edit("stiffness_fraction = [0.8, ", "stiffness_fraction = [-0.8, "),
        ("series.maxwell_slip.stiffness_fraction", ">= 0"),
    ),
}


@pytest.mark.parametrize("case", list(BAD_FILES))
def test_bad_coefficient_file_is_named_error(tmp_path: Path, case: str) -> None:
    edit, words = BAD_FILES[case]
    f = _write(tmp_path, edit(DEFAULT_TOML))
    with pytest.raises(CoefficientFileError) as info:
        load_catalogue(f)
    msg = str(info.value)
    assert str(f) in msg, msg
    for w in words:
        assert w in msg, f"{w!r} not in {msg!r}"


@pytest.mark.parametrize("case", ["misspelt section", "string false", "diameter in metres"])
def test_bad_coefficient_file_on_the_cli(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str], case: str
) -> None:
    """``fsarm shafts`` and ``fsarm run`` stop with one named error (exit 2), no traceback."""
    edit, words = BAD_FILES[case]
    f = _write(tmp_path, edit(DEFAULT_TOML))
    for args in (
        ("shafts", "--shaft-file", str(f)),
        ("run", "fig14-sine", "--duration", "0.01", "--out", str(tmp_path / "o")),
    ):
        if args[0] == "run":
            args = (*args, "--shaft-file", str(f))
        assert run_fsarm(monkeypatch, *args) == 2
        err = _oneline(capsys.readouterr().err)
        assert "Traceback" not in err
        assert words[0] in err and str(f) in err, err
    assert not (tmp_path / "o").exists()


def test_every_allowed_spelling_of_the_units_loads(tmp_path: Path) -> None:
    for key, spellings in UNITS.items():
        for unit in spellings:
            default = UNITS[key][0]
            text = DEFAULT_TOML.replace(f'{key} = "{default}"', f'{key} = "{unit}"', 1)
            load_catalogue(_write(tmp_path, text))


def test_a_file_without_meta_is_read_in_the_catalogue_units(tmp_path: Path) -> None:
    start = DEFAULT_TOML.index("\n[meta]\n")
    end = DEFAULT_TOML.index("\n[validity]\n")
    f = _write(tmp_path, DEFAULT_TOML[:start] + DEFAULT_TOML[end:])
    assert load_catalogue(f).shaft() == load_catalogue().shaft()


def test_the_files_maxwell_slip_flag_takes_effect(tmp_path: Path) -> None:
    """``enabled = true`` switches the elements on wherever the caller does not decide
    (series_hysteresis=None: sweeps, campaigns, the CLI without --[no-]series-hysteresis); an
    explicit True/False from the caller wins."""
    on = load_catalogue()  # the built-in file switches them on (seed 000's series hysteresis)
    off = load_catalogue(_write(tmp_path, _edit("enabled = true", "enabled = false")(DEFAULT_TOML)))
    assert not off.slip_enabled and on.slip_enabled
    assert off.shaft().slip_k == (0.0, 0.0, 0.0)
    assert min(on.shaft().slip_k) > 0.0
    assert on.shaft(series_hysteresis=False).slip_k == (0.0, 0.0, 0.0)
    assert off.shaft(series_hysteresis=True).slip_k == on.shaft().slip_k
    assert off.shaft().source == str(tmp_path / "mine.toml")


def test_the_built_in_file_still_loads() -> None:
    cat = load_catalogue()
    assert len(cat.shafts) == 9 and cat.slip_enabled
    assert 0.0 < cat.slip_unwinding_ratio < 1.0 and cat.bend_friction_per_rad > 0.0
    assert cat.bend_limit_rad == pytest.approx(2.0 * math.pi / 3.0)


# ------------------------------------------------------------------ validity.bend_rad


@pytest.fixture
def narrow_bend_file(tmp_path: Path) -> Path:
    """A file whose bend validity (+-0.3 rad) excludes fig14-sine's q2 = 45 deg."""
    old = "bend_rad = [-2.0943951023931953, 2.0943951023931953]"
    return _write(tmp_path, _edit(old, "bend_rad = [-0.3, 0.3]")(DEFAULT_TOML), "narrow.toml")


def test_run_honours_the_files_bend_range(narrow_bend_file: Path) -> None:
    cfg = SimConfig(shaft=load_catalogue(narrow_bend_file).shaft())
    with pytest.raises(ShaftRangeError) as info:
        build_model(cfg, HOLD)
    msg = str(info.value)
    assert str(narrow_bend_file) in msg and "validity.bend_rad" in msg and "q2" in msg
    build_model(cfg, hold_table(0.0, 0.25, 0.4))  # inside: builds
    build_model(cfg, hold_table(0.0, -0.25, 0.4))
    # a transmission not routed over joint 2 carries no shaft there: the file's bend range is moot
    build_model(cfg.with_(transmission="qa-joint"), HOLD)
    with pytest.raises(ShaftRangeError):  # routed over joint 2: checked
        build_model(cfg.with_(transmission="tendon-sheath"), HOLD)


def test_sweep_and_run_reject_the_same_file_with_the_same_check(
    narrow_bend_file: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    with pytest.raises(sw.SweepSpecError) as info:
        sw.build_spec(fixed=["bend_deg=45"], shaft_file=str(narrow_bend_file))
    sweep_msg = str(info.value)
    code = run_fsarm(
        monkeypatch,
        "run",
        "fig14-sine",
        "--duration",
        "0.01",
        "--shaft-file",
        str(narrow_bend_file),
        "--out",
        str(narrow_bend_file.parent / "o"),
    )
    run_msg = _oneline(capsys.readouterr().err)
    assert code == 2
    for msg in (sweep_msg, run_msg):
        assert "outside the validity range" in msg and "validity.bend_rad" in msg
        assert str(narrow_bend_file) in msg and "0.7854 rad (45.0 deg)" in msg


def test_bend_check_refuses_non_finite_angles() -> None:
    cat = load_catalogue()
    with pytest.raises(ShaftRangeError, match="finite"):
        cat.check_bend(math.nan)
    with pytest.raises(ShaftRangeError, match="finite"):
        cat.shaft().check_bend(np.array([0.1, math.inf]))
    cat.check_bend([-2.0, 0.0, 2.0])  # inside +-2 pi / 3


# ================================================================== transmission parameters


def _params() -> list[tuple[str, Param]]:
    return [(n, p) for n in NAMES for p in transmissions.get(n).params]


def _outside_cases() -> list[tuple[str, str, float]]:
    """Every declared parameter set just outside each finite end of its range."""
    return [(n, p.name, v) for n, p in _params() for v in p.bounds.just_outside()]


def _block_or_build(tr: Transmission, overrides: dict[str, float]) -> None:
    """The real path for a run (SimConfig -> build_model); the flexible shaft, whose plant comes
    from SimConfig.shaft, through its generic block."""
    if tr.name == transmissions.DEFAULT:
        tr.block(overrides)
    else:
        build_model(
            SimConfig(transmission=tr.name, transmission_params=tuple(overrides.items())), HOLD
        )


@pytest.mark.parametrize(("name", "param"), [(n, p.name) for n, p in _params()])
def test_every_parameter_declares_a_range_with_a_reason(name: str, param: str) -> None:
    p = next(q for q in transmissions.get(name).params if q.name == param)
    assert isinstance(p.bounds, Bounds)
    assert len(p.bounds.why) > 15, "say why the range is what it is"
    assert p.bounds.lo < p.bounds.hi
    assert p.bounds.contains(p.value), f"default {p.value!r} outside {p.bounds.text()}"


@pytest.mark.parametrize(("name", "param", "value"), _outside_cases())
def test_parameter_just_outside_its_range_is_named_error(
    name: str, param: str, value: float
) -> None:
    tr = transmissions.get(name)
    p = next(q for q in tr.params if q.name == param)
    with pytest.raises(TransmissionError) as info:
        _block_or_build(tr, {param: value})
    msg = str(info.value)
    for word in (repr(name), param, repr(value), p.bounds.text()):
        assert word in msg, f"{word!r} not in {msg!r}"


@pytest.mark.parametrize(("name", "param"), [(n, p.name) for n, p in _params()])
def test_non_finite_parameter_is_named_error(name: str, param: str) -> None:
    tr = transmissions.get(name)
    for bad in (math.nan, math.inf, -math.inf):
        with pytest.raises(TransmissionError) as info:
            tr.block({param: bad})
        assert param in str(info.value) and "finite" in str(info.value)


@pytest.mark.parametrize("name", NAMES)
def test_defaults_still_build_without_warnings(name: str) -> None:
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        model = build_model(SimConfig(transmission=name), HOLD)
    assert model.nu > 0


# The failures reported in issue 17 (and their neighbours), on the path a run takes. Each must
# name the transmission and the parameter(s); the last ones are cross-parameter checks.
REPORTED: list[tuple[str, dict[str, float], tuple[str, ...]]] = [
    ("tendon-sheath", {"mu": -1.0}, ("mu", "-1.0", "[0, 1]")),
    ("tendon-sheath", {"tendon_length_m": -1.0}, ("tendon_length_m", "-1.0", "(0, 10]")),
    ("tendon-sheath", {"tendon_length_m": 0.0}, ("tendon_length_m", "0.0")),
    ("tendon-sheath", {"pulley_radius_m": 0.0}, ("pulley_radius_m", "0.0")),
    ("tendon-sheath", {"tendon_radius_m": 0.0}, ("tendon_radius_m", "0.0")),
    ("tendon-sheath", {"youngs_modulus_pa": 0.0}, ("youngs_modulus_pa", "0.0")),
    ("tendon-sheath", {"presliding_rad": 0.0}, ("presliding_rad", "0.0")),
    ("tendon-sheath", {"scale": 0.0}, ("scale", "0.0")),
    ("tendon-sheath", {"pulley_radius_m": 25.0}, ("pulley_radius_m", "25.0", "mm given as m")),
    ("tendon-sheath", {"sheath_length_m": 2.0}, ("sheath_length_m", "tendon_length_m")),
    ("qa-joint", {"sigma_cmd": -10.0}, ("sigma_cmd", "-10.0")),
    ("qa-joint", {"sigma_cmd": 0.0}, ("sigma_cmd", "0.0")),
    ("qa-joint", {"sigma_tau_s": 0.0}, ("sigma_tau_s", "0.0")),
    ("qa-joint", {"presliding_rad": 0.0}, ("presliding_rad", "0.0")),
    ("qa-joint", {"b_exp": 0.0}, ("b_exp", "0.0")),
    ("qa-joint", {"a_s": 0.0}, ("a_s", "0.0")),
    ("qa-joint", {"sigma_min": 0.0}, ("sigma_min", "0.0")),
    ("qa-joint", {"sigma_min": 0.3}, ("sigma_min", "0.3", "sigma_max")),
    ("qa-joint", {"sigma_min": 0.2, "sigma_max": 0.1}, ("sigma_min", "sigma_max")),
    ("qa-joint", {"sigma_cmd": math.radians(40.0)}, ("sigma_cmd", "40 deg", "preset range")),
    ("qa-joint", {"sigma_max": 0.1}, ("sigma_cmd", "preset range")),  # default 15 deg > max
    ("rtca", {"c": -1.0}, ("c", "dissipative")),
    ("rtca", {"x_dead_neg": 1.5}, ("x_dead_neg", "x_fit_neg")),
    ("rtca", {"x_dead_neg": 0.0}, ("x_dead_neg", "falling torque")),
    ("rtca", {"a1_pos": 4.2}, ("a0_pos", "falling torque")),
    ("magnetic-spring", {"d": 0.025}, ("d", "decouples")),
    ("magnetic-spring", {"b1": 0.0}, ("b1", "0.0")),
    ("magnetic-spring", {"b2": -1.0}, ("b1", "b2", "stable equilibrium")),
]


@pytest.mark.parametrize(("name", "overrides", "words"), REPORTED)
def test_reported_parameter_failures_are_named_errors(
    name: str, overrides: dict[str, float], words: tuple[str, ...]
) -> None:
    with pytest.raises(TransmissionError) as info:
        build_model(
            SimConfig(transmission=name, transmission_params=tuple(overrides.items())), HOLD
        )
    msg = str(info.value)
    assert repr(name) in msg
    for w in words:
        assert w in msg, f"{w!r} not in {msg!r}"


@pytest.mark.parametrize(
    "args",
    [
        ("tendon-sheath", "mu=-1"),
        ("tendon-sheath", "tendon_length_m=-1"),
        ("tendon-sheath", "pulley_radius_m=0"),
        ("qa-joint", "sigma_cmd=-10"),
        ("qa-joint", "sigma_min=0.3"),
        ("qa-joint", "sigma_tau_s=0"),
    ],
)
def test_reported_cli_cases_exit_2_with_one_line(
    tmp_path: Path,
    monkeypatch: pytest.MonkeyPatch,
    capsys: pytest.CaptureFixture[str],
    args: tuple[str, str],
) -> None:
    """``fsarm run fig14-sine --duration 0.2 --transmission T --tr-param P=V`` as reported."""
    name, item = args
    code = run_fsarm(
        monkeypatch,
        "run",
        "fig14-sine",
        "--duration",
        "0.2",
        "--out",
        str(tmp_path / "o"),
        "--transmission",
        name,
        "--tr-param",
        item,
    )
    captured = capsys.readouterr()
    err = _oneline(captured.err)
    assert code == 2
    assert f"transmission '{name}'" in err and item.split("=")[0] in err
    assert "Traceback" not in err and "Warning" not in err
    assert not (tmp_path / "o").exists()  # refused before the run: nothing written


# the cases that already passed stay passing
def test_unknown_names_and_misplaced_parameters_stay_named_errors() -> None:
    with pytest.raises(TransmissionError, match="known: flexible-shaft"):
        build_model(SimConfig(transmission="harmonic-drive"), HOLD)
    for name in NAMES:
        with pytest.raises(TransmissionError, match="allowed"):
            transmissions.get(name).block({"no_such_parameter": 1.0})
    with pytest.raises(FsarmError, match=r"eq\. 3 must stay > 0"):  # an override, checked
        build_model(SimConfig(transmission_params=(("k_pos", 1.0),)), HOLD)


def test_a_controller_copy_out_of_range_is_caught_too() -> None:
    cfg = SimConfig(transmission="tendon-sheath", controller_transmission_params=(("mu", -0.5),))
    with pytest.raises(TransmissionError, match="mu"):
        build_model(cfg, HOLD)


def test_bounds_text_and_just_outside() -> None:
    b = Bounds(0.0, 1.0, "why", lo_open=True)
    assert b.text() == "(0, 1]"
    assert not b.contains(0.0) and b.contains(1.0) and not b.contains(math.nan)
    assert all(not b.contains(v) for v in b.just_outside())
    assert Bounds(-math.inf, math.inf, "why").just_outside() == ()
    assert Bounds(0.0, math.inf, "why").text() == "[0, inf)"
