"""neepp_tools.exr round trip and reading the shared references."""
import numpy as np
import pytest

from neepp_tools import REFERENCES, SCENES_DIR, exr, reference_path


def _have_backend():
    try:
        import mitsuba  # noqa: F401
        return True
    except ImportError:
        try:
            import OpenEXR  # noqa: F401
            return True
        except ImportError:
            return False


pytestmark = pytest.mark.skipif(not _have_backend(), reason="neither mitsuba nor OpenEXR is installed")


def test_round_trip(tmp_path):
    rng = np.random.default_rng(0)
    img = rng.random((7, 5, 3)).astype(np.float32) * 100
    p = tmp_path / "x.exr"
    exr.write_exr(p, img)
    back = exr.read_exr(p)
    assert back.shape == (7, 5, 3) and back.dtype == np.float32
    np.testing.assert_array_equal(back, img)


@pytest.mark.skipif(not (SCENES_DIR / "cornell-box").exists(), reason="shared scenes not found")
def test_references_have_listed_resolution():
    for scene, (w, h, _, _) in REFERENCES.items():
        img = exr.read_exr(reference_path(scene))
        assert img.shape == (h, w, 3), scene
        assert np.isfinite(img).all() and img.min() >= 0, scene
