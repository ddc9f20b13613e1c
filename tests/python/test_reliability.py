"""Issue 14's (and 29's) Python findings (docs/reliability.md): a --threads ceiling (threads=100000 used to
abort the interpreter in tbb::task_arena's destructor), a NUL byte in a path (write_image wrote
"a"), and filter parameters whose inverse squares overflowed (the whole output NaN)."""
import os

import numpy as np
import pytest

import atrous


def test_threads_has_a_ceiling():
    with pytest.raises(ValueError, match="threads"):
        atrous.render("cornell", width=8, height=8, spp=1, threads=100000)
    with pytest.raises(ValueError, match="threads"):
        next(atrous.render_sequence("cornell-moving", 2, width=8, height=8, threads=100000))


def test_nul_in_a_path_is_refused(tmp_path):
    img = np.zeros((2, 2, 3), np.float32)
    with pytest.raises(ValueError, match="NUL"):
        atrous.write_image(str(tmp_path / "a\x00b.exr"), img)
    assert not os.path.exists(tmp_path / "a")
    with pytest.raises(ValueError, match="NUL"):
        atrous.read_image(str(tmp_path / "a\x00b.exr"))


@pytest.mark.parametrize("name", ["sigma_normal", "sigma_position", "sigma_depth", "albedo_epsilon"])
def test_tiny_filter_parameters_are_rejected(name):
    b = atrous.render("cornell", width=16, height=16, spp=2)
    kw = dict(albedo=b["albedo"], normal=b["normal"], position=b["position"], depth=b["depth"])
    with pytest.raises(ValueError):
        atrous.denoise(b["color"], method="eaw", **kw, **{name: 1e-20})
    out = atrous.denoise(b["color"], method="eaw", **kw, **{name: 1e-6})
    assert np.isfinite(out).all()


def test_a_directory_or_a_device_as_weights_is_a_value_error(tmp_path):
    """Issue 29, case 9: a directory as the weight file raised RuntimeError ("basic_filebuf::underflow
    error reading the file: Is a directory"); /dev/zero would have been read for ever."""
    b = atrous.render("cornell", width=8, height=8, spp=1)
    (tmp_path / "weights").mkdir()
    with pytest.raises(ValueError, match="weights: is a directory"):
        atrous.denoise(b["color"], method="learned", learned_weights=tmp_path / "weights")
    with pytest.raises(ValueError, match="not a regular file"):
        atrous.denoise(b["color"], method="learned", learned_weights="/dev/zero")
