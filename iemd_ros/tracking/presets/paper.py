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

"""
The system of the paper (Yao & Dani, section 6.1).

Algorithm 1 with eq. (10)'s gradient, the EMD scale variants (+-2 %), four particles around the
prediction, Algorithm 2; no filter, colour model, optical flow or motion prior.
"""
from iemd_ros.tracking.config import Gradient, ScaleEstimator, TrackerConfig


def parameters() -> TrackerConfig:
    """
    Return the configuration of the paper's system (see the module docstring).

    Returns
    -------
    TrackerConfig
        The paper's gradient, EMD scale variants and particles; no discriminative extension.

    """
    return TrackerConfig(
        n_iter=20,
        gradient=Gradient.PAPER,
        scale_estimator=ScaleEstimator.EMD,
        scale_step=0.02,
        scale_range=0.02,
        n_particles=4,
        flow_start=False,
        translation_weight=0.0,
        colour_weight=0.0,
        colour_merge=0.0,
        motion_weight=0.0,
        update_confidence=0.0,
    )
