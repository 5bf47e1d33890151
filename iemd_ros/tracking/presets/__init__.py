"""Named tracker configurations, one module per variant, each with ``parameters() -> TrackerConfig``."""
