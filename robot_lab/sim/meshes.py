"""Mesh files (.stl, .obj, .dae) into MuJoCo mesh assets, for URDF links and SDF models alike.

MuJoCo reads STL, OBJ and MSH itself but not COLLADA, and not `package://` or `model://`
paths; trimesh reads all three formats into vertices and faces, which a spec takes as a
user mesh. Where a mesh comes from is resolved here once: `package://` through the ament
index, `model://` on the resource path, `file://` and plain paths (relative to the file
that names them).
"""

from __future__ import annotations

import logging
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import mujoco  # type: ignore[import-untyped]  # no stubs nor py.typed

from robot_lab.sim.xml_tree import Node, Warn

__all__ = ['add_mesh', 'resolve_mesh']


def resolve_mesh(uri: str, node: Node, warn: Warn, models: Sequence[Path] = (),
                 base: Path | None = None) -> Path | None:
    """The file a mesh URI names, or None (with a warning naming `node`) if none does."""
    path: Path | None
    if uri.startswith('package://'):
        from robot_lab.pkg.index import package_share  # the index imports kit_packages

        package, _, rest = uri.removeprefix('package://').partition('/')
        try:
            path = package_share(package) / rest
        except Exception:  # PackageNotFoundError: said as this mesh's warning
            warn(f'{node.where}: mesh {uri!r}: package {package!r} is not in the ament index; '
                 f'this collision is left out')
            return None
        warn(f'{node.where}: mesh {uri!r} read from {path} (package:// resolved by the kit)')
        return path
    if uri.startswith('model://'):
        rest = uri.removeprefix('model://')
        path = next((folder / rest for folder in models if (folder / rest).is_file()), None)
        if path is None:
            warn(f'{node.where}: mesh {uri!r} is on no resource path (GZ_SIM_RESOURCE_PATH); '
                 f'this collision is left out')
        return path
    path = Path(uri.removeprefix('file://')).expanduser()
    return base / path if base is not None and not path.is_absolute() else path


def add_mesh(spec: mujoco.MjSpec, path: Path, scale: Sequence[float], owner: str,
             node: Node, warn: Warn) -> str:
    """The mesh file as a spec asset; its name, or '' (with a warning) if it cannot be read."""
    try:
        import trimesh

        # the tutorials' COLLADA files name textures they do not ship: trimesh logs a
        # traceback for each, and textures do not collide
        quiet = logging.getLogger('trimesh')
        level = quiet.level
        quiet.setLevel(logging.CRITICAL)
        try:
            loaded = trimesh.load(str(path), force='mesh')
        finally:
            quiet.setLevel(level)
        mesh_data: Any = loaded  # a Trimesh: force='mesh'
        vertices = mesh_data.vertices.flatten().tolist()
        faces = mesh_data.faces.flatten().tolist()
    except Exception as error:  # trimesh raises many kinds; the warning names the cause
        warn(f'{node.where}: mesh {path.name} of {owner} could not be read '
             f'({type(error).__name__}: {error}); this collision is left out')
        return ''
    asset = spec.add_mesh()
    asset.name = f'{owner}::mesh{len(spec.meshes)}'
    asset.uservert = vertices
    asset.userface = faces
    asset.scale = list(scale)
    if path.suffix.lower() == '.dae':
        warn(f'{node.where}: {path.name} of {owner} converted from COLLADA with trimesh')
    return str(asset.name)
