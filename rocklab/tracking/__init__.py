"""rocklab.tracking (see the package docs)."""

from ._config import (BoardConfig, MotionConfig, ObjectConfig, ReferenceConfig, TargetsConfig,
                      TrackConfig, VideoConfig, load_track_config)

__all__: list[str] = [
    # video tracking (helper "track")
    "TrackConfig", "VideoConfig", "TargetsConfig", "ReferenceConfig", "BoardConfig",
    "MotionConfig", "ObjectConfig", "load_track_config",
]
