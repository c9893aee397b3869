"""aiorobot.fusion — see API.md."""

__all__: list[str] = []
