"""Assets for the Foxglove app (meshes and textures a URDF names): which URIs may be read, and where.

``package://<pkg>/<path>`` is looked up in ``<root>/<pkg>/<path>`` for each configured root (a
folder holding package folders, or a package folder itself when its name is ``<pkg>``), then in
the packages' share folders (``<prefix>/share/<pkg>`` for each prefix of ``AMENT_PREFIX_PATH``).
``file://<absolute path>`` is read only when the path (symbolic links resolved) lies under one of
the roots or share folders. Anything else (``http://``, a relative path, ``..`` escaping a root)
is refused with the reason, which the app shows. Pure: no runtime, tested on its own.
"""

from __future__ import annotations

import os
from collections.abc import Sequence
from pathlib import Path
from urllib.parse import unquote, urlsplit

__all__ = ["AssetRefused", "AssetResolver"]


class AssetRefused(ValueError):
    """A URI that is not served: outside the roots, an unsupported scheme, or not found."""


class AssetResolver:
    """``resolver(uri) -> bytes`` (foxglove-sdk's asset handler); raises :class:`AssetRefused`."""

    def __init__(self, roots: Sequence[str | os.PathLike[str]] = (), *, ament_prefix_path: str | None = None) -> None:
        self.roots: list[Path] = []
        for root in roots:
            path = Path(root).expanduser()
            if not path.is_dir():
                raise ValueError(f"asset_roots: expected a folder, found {str(root)!r} (not a directory)")
            self.roots.append(path.resolve())
        prefixes = os.environ.get("AMENT_PREFIX_PATH", "") if ament_prefix_path is None else ament_prefix_path
        self.share_dirs = [Path(p).resolve() / "share" for p in prefixes.split(os.pathsep) if p and (Path(p) / "share").is_dir()]

    def __repr__(self) -> str:
        return f"<AssetResolver roots={[str(r) for r in self.roots]} shares={len(self.share_dirs)}>"

    def __call__(self, uri: str) -> bytes:
        return self.resolve(uri).read_bytes()

    def resolve(self, uri: str) -> Path:
        """The file ``uri`` names, once it is known to be allowed and to exist."""
        parts = urlsplit(uri)
        if parts.scheme == "package":
            return self._package(uri, parts.netloc, unquote(parts.path).lstrip("/"))
        if parts.scheme == "file":
            return self._file(uri, Path(unquote(parts.path)))
        raise AssetRefused(f"asset {uri!r} refused: expected a package:// or file:// URI")

    def _package(self, uri: str, package: str, rel: str) -> Path:
        if not package or not rel:
            raise AssetRefused(f"asset {uri!r} refused: expected package://<package>/<path>")
        bases = [r for r in self.roots if r.name == package] + [r / package for r in self.roots] + [s / package for s in self.share_dirs]
        for base in bases:
            candidate = (base / rel).resolve()
            if candidate.is_relative_to(base.resolve()) and candidate.is_file():
                return candidate
        where = ", ".join(str(b) for b in bases) or "no asset_roots and no AMENT_PREFIX_PATH share folders"
        raise AssetRefused(f"asset {uri!r} not found: looked for {rel} in {where}")

    def _file(self, uri: str, path: Path) -> Path:
        if not path.is_absolute():
            raise AssetRefused(f"asset {uri!r} refused: expected an absolute file:// path")
        real = path.resolve()
        allowed = [*self.roots, *self.share_dirs]
        if not any(real.is_relative_to(base) for base in allowed):
            where = ", ".join(str(b) for b in allowed) or "none configured"
            raise AssetRefused(f"asset {uri!r} refused: file:// is served only under the asset roots ({where})")
        if not real.is_file():
            raise AssetRefused(f"asset {uri!r} not found")
        return real
