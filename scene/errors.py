"""The one error of the scene room: a scene file unreadable or holding an invalid value."""
from __future__ import annotations

from common.errors import InputError


class SceneError(InputError):
    """The scene file is unreadable or holds an invalid value."""
