# Copyright 2026 iemd_ros authors
# SPDX-License-Identifier: BSD-3-Clause
#
# Redistribution and use in source and binary forms, with or without
# modification, are permitted provided that the following conditions are met:
#
#    * Redistributions of source code must retain the above copyright
#      notice, this list of conditions and the following disclaimer.
#
#    * Redistributions in binary form must reproduce the above copyright
#      notice, this list of conditions and the following disclaimer in the
#      documentation and/or other materials provided with the distribution.
#
#    * Neither the name of the iemd_ros authors nor the names of its
#      contributors may be used to endorse or promote products derived from
#      this software without specific prior written permission.
#
# THIS SOFTWARE IS PROVIDED BY THE COPYRIGHT HOLDERS AND CONTRIBUTORS "AS IS"
# AND ANY EXPRESS OR IMPLIED WARRANTIES, INCLUDING, BUT NOT LIMITED TO, THE
# IMPLIED WARRANTIES OF MERCHANTABILITY AND FITNESS FOR A PARTICULAR PURPOSE
# ARE DISCLAIMED. IN NO EVENT SHALL THE COPYRIGHT HOLDER OR CONTRIBUTORS BE
# LIABLE FOR ANY DIRECT, INDIRECT, INCIDENTAL, SPECIAL, EXEMPLARY, OR
# CONSEQUENTIAL DAMAGES (INCLUDING, BUT NOT LIMITED TO, PROCUREMENT OF
# SUBSTITUTE GOODS OR SERVICES; LOSS OF USE, DATA, OR PROFITS; OR BUSINESS
# INTERRUPTION) HOWEVER CAUSED AND ON ANY THEORY OF LIABILITY, WHETHER IN
# CONTRACT, STRICT LIABILITY, OR TORT (INCLUDING NEGLIGENCE OR OTHERWISE)
# ARISING IN ANY WAY OUT OF THE USE OF THIS SOFTWARE, EVEN IF ADVISED OF THE
# POSSIBILITY OF SUCH DAMAGE.

"""The image pyramid converts a uint8 frame's grey levels only where level-0 windows read them."""
from iemd_ros.tracking.appearance import ImagePyramid, to_gray
import numpy as np
import pytest


@pytest.mark.parametrize('shape', [(720, 1280), (37, 53)])
def test_a_pyramid_of_grey_levels_samples_as_the_converted_frame(shape):
    """
    A pyramid of uint8 grey levels samples the templates of the frame :func:`to_gray` converts.

    Windows anywhere (across the edges, wholly outside, turned) and at levels 0 to 3: the scaled
    templates (a remap) bit for bit, a template (OpenCV's ``warpAffine``, whose float32
    coordinates round differently on a crop: 2^-13 px at 1280 px) within 2^-12 of a grey level
    on this noise, whose grey levels change by up to 1 per px.  Level-0 windows read crops only;
    the whole frame is converted once a level above is needed.
    """
    rng = np.random.default_rng(7)
    grey = rng.integers(0, 256, shape, dtype=np.uint8)
    h, w = shape
    windows = [
        (rng.uniform(-0.3, 1.3, 2) * (w, h), rng.uniform(4.0, 60.0, 2), rng.uniform(-3.2, 3.2))
        for _ in range(60)
    ] + [((-80.0, h / 2), (20.0, 30.0), 0.0), ((w + 50.0, h + 40.0), (30.0, 20.0), 0.3)]
    lazy, converted = ImagePyramid(grey), ImagePyramid(to_gray(grey))
    factors = [0.95, 1.0, 1.05]

    def same(window, template=(32, 32)):
        np.testing.assert_allclose(
            lazy.sample(*window[:2], template, window[2]),
            converted.sample(*window[:2], template, window[2]),
            rtol=0,
            atol=2.0 ** -12,
        )
        np.testing.assert_array_equal(
            lazy.sample_scales(*window[:2], template, factors, window[2]),
            converted.sample_scales(*window[:2], template, factors, window[2]),
        )

    for window in windows:
        same(window)
        same(window, (24, 40))
    assert lazy._levels[0] is None  # level 0 only so far: crops
    for centre, size, angle in windows[:10]:
        same((centre, np.asarray(size) * 4.0, angle))  # levels 1-3
        same((centre, size, angle))
    assert lazy._levels[0] is not None
