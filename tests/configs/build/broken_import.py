"""A user module whose own import fails."""

import aiorobot_missing_dependency  # noqa: F401
