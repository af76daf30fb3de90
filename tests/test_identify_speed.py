"""The identification's fast paths against the calls they replace (issue 15, speed)."""

from __future__ import annotations

import numpy as np
import pytest

from clearjoint.identify.cycles import _hanning


@pytest.mark.parametrize("n", [16, 3600, 8221])
def test_cached_window_is_numpys_hanning_and_read_only(n: int) -> None:
    window = _hanning(n)
    assert window.tobytes() == np.hanning(n).tobytes()
    assert _hanning(n) is window  # made once per length
    with pytest.raises(ValueError, match="read-only"):
        window[0] = 1.0
