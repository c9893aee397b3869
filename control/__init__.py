"""aiorobot.control — see API.md."""

__all__: list[str] = []
