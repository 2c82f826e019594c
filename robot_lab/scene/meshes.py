"""Meshes a URDF or a marker names, found as ROS finds them and sent as bytes.

`package://pkg/meshes/x.dae` is resolved through the kit's ament index (the package's
share folder), `file:///abs/x.stl` is a path. The browser never fetches a file: the bytes
travel on the widget's own channel, so there is no HTTP route to break behind JupyterHub's
proxy or Binder (jupyterlab-urdf's users report 404s on meshes for that reason), and no
extra port. A COLLADA file's textures go with it; one that is missing is named once.
"""

from __future__ import annotations

import re
import xml.etree.ElementTree as ET
from pathlib import Path
from urllib.parse import unquote, urlparse

from robot_lab.errors import RobotLabError

__all__ = ['MeshFiles', 'mesh_uris', 'resolve_uri']

# Meshes larger than this are not sent (a phone-sized scan of a room would stall the page)
MAX_BYTES = 64 * 1024 * 1024


def resolve_uri(uri: str) -> Path:
    """The file a mesh URI names, as resource_retriever resolves it."""
    from robot_lab.pkg.index import package_share

    if uri.startswith('package://'):
        package, _, rest = uri[len('package://'):].partition('/')
        if not package or not rest:
            raise RobotLabError(f'{uri}: a package URI is package://<package>/<path>',
                                fix='write the package name, then the path in its share folder')
        return package_share(package) / unquote(rest)
    if uri.startswith('file://'):
        return Path(unquote(urlparse(uri).path))
    if '://' in uri:
        raise RobotLabError(f'{uri}: the view resolves package:// and file:// URIs only',
                            fix='name the mesh by its package (package://pkg/meshes/...)')
    return Path(uri)


def mesh_uris(root: ET.Element) -> list[str]:
    """Every mesh and texture file a parsed URDF names, in document order, once each."""
    seen: dict[str, None] = {}
    for tag in ('mesh', 'texture'):
        for node in root.iter(tag):
            name = node.get('filename')
            if name:
                seen.setdefault(name.strip(), None)
    return list(seen)


_INIT_FROM = re.compile(rb'<init_from>\s*([^<]+?)\s*</init_from>')


def collada_images(data: bytes) -> list[str]:
    """The image files a COLLADA document's <image> elements name."""
    names: dict[str, None] = {}
    for found in _INIT_FROM.findall(data):
        name = found.decode('utf-8', 'replace')
        if re.search(r'\.(png|jpe?g|tga|bmp|gif)$', name, re.IGNORECASE):
            names.setdefault(name, None)
    return list(names)


class MeshFiles:
    """The bytes behind each URI, read once; what was sent to the browser since its reset.

    `pack(uris, buffers)` returns the message's `meshes` entry: {uri: {index, textures}}
    with each file appended to `buffers`, or {uri: {index: None, error}} and the reason in
    `errors` (the status line shows it).
    """

    def __init__(self) -> None:
        self._cache: dict[str, bytes | str] = {}  # uri → bytes, or why it cannot be read
        self.sent: set[str] = set()
        self.errors: dict[str, str] = {}

    def forget_sent(self) -> None:
        self.sent.clear()

    def read(self, uri: str) -> bytes | str:
        if uri not in self._cache:
            try:
                path = resolve_uri(uri)
                size = path.stat().st_size
                if size > MAX_BYTES:
                    self._cache[uri] = f'{path} is {size >> 20} MiB (the view sends ≤ 64 MiB)'
                else:
                    self._cache[uri] = path.read_bytes()
            except RobotLabError as err:
                self._cache[uri] = str(err)
            except OSError as err:
                self._cache[uri] = f'{err.strerror}: {err.filename}'
        return self._cache[uri]

    def pack(self, uris: list[str], buffers: list[bytes]) -> dict[str, object]:
        out: dict[str, object] = {}
        for uri in uris:
            if uri in self.sent:
                continue
            self.sent.add(uri)
            data = self.read(uri)
            if isinstance(data, str):
                self.errors[uri] = data
                out[uri] = {'index': None, 'error': f'{uri}: {data}'}
                continue
            textures: dict[str, int] = {}
            if uri.lower().endswith('.dae'):
                textures = self._textures(uri, data, buffers)
            buffers.append(data)
            out[uri] = {'index': len(buffers) - 1, 'textures': textures}
        return out

    def _textures(self, uri: str, data: bytes, buffers: list[bytes]) -> dict[str, int]:
        """The COLLADA file's images that exist beside it (the browser maps the rest to a
        white pixel: urdf_tutorial's meshes name textures its repository lacks)."""
        base = uri.rsplit('/', 1)[0]
        found: dict[str, int] = {}
        missing = []
        for name in collada_images(data):
            relative = name[len('file://'):] if name.startswith('file://') else name
            target = relative if relative.startswith('/') else f'{base}/{relative}'
            image = self.read(target)
            if isinstance(image, str):
                missing.append(relative.rsplit('/', 1)[-1])
                continue
            buffers.append(image)
            found[name] = found[relative.rsplit('/', 1)[-1]] = len(buffers) - 1
        if missing:
            self.errors[uri] = (f'names textures its folder lacks ({", ".join(missing)}): '
                                'drawn without them')
        return found
