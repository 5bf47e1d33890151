"""The shipped tracker: iEMD with its discriminative extensions (the defaults of TrackerConfig)."""
from iemd_ros.tracking.config import TrackerConfig


def parameters() -> TrackerConfig:
    """The shipped tracker's configuration.

    Returns
    -------
    TrackerConfig
        ``TrackerConfig()``: the defaults.
    """
    return TrackerConfig()
