"""``rclpy.impl``: only ``logging_severity`` (the rest is rclpy's C binding, which aiorobot has no use for)."""

__all__: list[str] = []
