"""Names of a package loaded on first use (PEP 562), so importing the package imports none of its modules."""

from __future__ import annotations

import importlib


def lazy_names(package: str, exports: dict[str, str], namespace: dict):
    """``__getattr__`` and ``__dir__`` for `package`, whose public names are in modules ``exports[name]``
    (relative to it); a name, once loaded, is kept in the package's `namespace`."""

    def __getattr__(name: str):
        if name not in exports:
            raise AttributeError(f"module {package!r} has no attribute {name!r}")
        value = getattr(importlib.import_module(f".{exports[name]}", package), name)
        namespace[name] = value
        return value

    def __dir__() -> list[str]:
        return sorted(set(namespace) | set(exports))

    return __getattr__, __dir__
