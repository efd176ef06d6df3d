"""``track.toml`` as the tracker reads it: the schema, reader and writer live in
:mod:`rocklab.config` (``rocklab/config/_track_toml.py``, which documents the conventions)."""

from __future__ import annotations

from ...config import (
    OBJECT_KINDS,
    TARGET_STYLES,
    BoardConfig,
    MotionConfig,
    ObjectConfig,
    ReferenceConfig,
    TargetsConfig,
    TrackConfig,
    VideoConfig,
    load_track_config,
    schema_markdown,
)

__all__ = [
    "TrackConfig",
    "VideoConfig",
    "TargetsConfig",
    "ReferenceConfig",
    "BoardConfig",
    "MotionConfig",
    "ObjectConfig",
    "load_track_config",
    "schema_markdown",
    "TARGET_STYLES",
    "OBJECT_KINDS",
]
