"""The package checks, one module each; importing this package registers them all.

Every module here is imported (no list to keep), so a new check is a module with a
`@register('its_id', stage=...)` function and a line in the rubric.
"""

from __future__ import annotations

import importlib
import pkgutil

for _module in pkgutil.iter_modules(__path__):
    importlib.import_module(f'{__name__}.{_module.name}')
