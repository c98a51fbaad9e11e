"""Loop plot images: frame rules, and the data -> pixel map checked against the drawn image."""

from __future__ import annotations

import io

import numpy as np
import pytest
from PIL import Image as PILImage

from fsarm_sim.errors import InvalidParameterError
from fsarm_sim.review.loop_plot import LoopCurve, frame, render_loop


def test_frame_holds_zero_when_that_keeps_the_data_over_half() -> None:
    lo, hi = frame([np.array([1.0, 3.0])])  # zero 1 span away: brought in
    assert lo < 0.0 < hi and lo == pytest.approx(-0.06 * 3.0)
    lo, hi = frame([np.array([-1.97, -1.63])])  # far from zero (a preloaded shaft): not
    assert hi < 0.0 and (1.97 - 1.63) / (hi - lo) == pytest.approx(1 / 1.12)
    lo, hi = frame([np.array([-2.0, 5.0]), np.array([np.nan, 7.0])])  # NaN ignored
    assert lo == pytest.approx(-2.0 - 0.06 * 9.0) and hi == pytest.approx(7.0 + 0.06 * 9.0)
    lo, hi = frame([np.array([0.3, 0.3])])  # a constant: still a frame of positive width
    assert hi > lo


def _dark(png: bytes) -> np.ndarray:
    with PILImage.open(io.BytesIO(png)) as im:
        a = np.asarray(im.convert("RGB"), dtype=int)
    return np.all(a < 120, axis=-1)


def test_pixel_map_puts_the_origin_on_the_drawn_axes() -> None:
    """The map's (0, 0) lies on the dark zero lines of the rendered image, and a curve's
    end points land on pixels the curve was drawn on."""
    x = np.linspace(-2.0, 3.0, 50)
    img = render_loop(
        [LoopCurve(x, 0.4 * x, "a line", "#000000", "-", 2.0)],
        title="t",
        xlabel="x",
        ylabel="y",
        size_px=(400, 300),
    )
    dark = _dark(img.png)
    assert dark.shape == (img.height, img.width) == (300, 400)
    u0, v0 = img.to_pixels(np.array(0.0), np.array(0.0))
    iu, iv = round(float(u0)), round(float(v0))
    assert dark[iv, iu - 20 : iu + 20].all()  # horizontal zero line
    assert dark[iv - 20 : iv + 20, iu].all()  # vertical zero line
    for xe in (-2.0, 3.0):
        u, v = img.to_pixels(np.array(xe), np.array(0.4 * xe))
        assert dark[round(float(v)) - 1 : round(float(v)) + 2, round(float(u))].any()
    # y up in the data is v down in the image
    assert img.by < 0.0 < img.bx


def test_render_needs_a_curve_and_a_sane_size() -> None:
    with pytest.raises(InvalidParameterError, match="at least one curve"):
        render_loop([], title="t", xlabel="x", ylabel="y")
    c = LoopCurve(np.zeros(2), np.zeros(2), "c", "#000000")
    with pytest.raises(InvalidParameterError, match="size"):
        render_loop([c], title="t", xlabel="x", ylabel="y", size_px=(10, 10))
