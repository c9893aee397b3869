"""aiorobot.perception — see API.md."""

__all__: list[str] = []
