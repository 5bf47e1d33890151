"""The system of the paper (Yao & Dani, section 6.1): Algorithm 1 with eq. (10)'s gradient, the EMD scale variants
(+-2 %), four particles around the prediction, Algorithm 2; no filter, colour model, optical flow or motion prior."""
from iemd_ros.tracking.config import Gradient, ScaleEstimator, TrackerConfig


def parameters() -> TrackerConfig:
    """The configuration of the paper's system (see the module docstring).

    Returns
    -------
    TrackerConfig
        The paper's gradient, EMD scale variants and particles; no discriminative extension.
    """
    return TrackerConfig(
        gradient=Gradient.PAPER,
        scale_estimator=ScaleEstimator.EMD,
        scale_step=0.02,
        scale_range=0.02,
        n_particles=4,
        flow_start=False,
        translation_weight=0.0,
        colour_weight=0.0,
        motion_weight=0.0,
        update_confidence=0.0,
    )
