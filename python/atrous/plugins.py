"""Plugins: Python modules or files that add still methods with atrous.register_method, loaded by
the front-ends that take --plugin (python -m atrous.eval, the farm). A farm job loads them on the
driver (so that their methods pass its checks) and in every worker before it runs an item of that
job (a worker is another process: the registry is per process). A file is loaded once per process
under a name made from its absolute path; on a cluster it must be at that path on every node (a
shared file system), a module importable on every node. A plugin that cannot be loaded is a
ValueError naming it.
"""
from __future__ import annotations

import hashlib
import importlib
import importlib.util
import sys
from pathlib import Path
from typing import Any, List


__all__ = ["resolve_plugins", "load_plugins", "PluginError"]


class PluginError(ValueError):
    """A plugin that cannot be found or loaded."""


def resolve_plugins(plugins: Any) -> List[str]:
    """The job's plugins as the workers will load them: files as absolute paths, module names as given."""
    if plugins is None:
        return []
    items = [plugins] if isinstance(plugins, str) else list(plugins)
    out = []
    for p in items:
        p = str(p)
        if not p:
            raise PluginError("--plugin: empty")
        out.append(str(Path(p).resolve()) if p.endswith((".py", ".so")) or "/" in p else p)
    return out


def _load_file(spec: str) -> None:
    path = Path(spec)
    name = "atrous_plugin_" + hashlib.sha1(str(path).encode()).hexdigest()[:16]
    if name in sys.modules:
        return
    if not path.is_file():
        raise PluginError(f"--plugin {spec}: no such file")
    loader = importlib.util.spec_from_file_location(name, path)
    if loader is None or loader.loader is None:
        raise PluginError(f"--plugin {spec}: not a Python file")
    mod = importlib.util.module_from_spec(loader)
    sys.modules[name] = mod
    try:
        loader.loader.exec_module(mod)
    except Exception as e:
        del sys.modules[name]
        raise PluginError(f"--plugin {spec}: {type(e).__name__}: {e}") from None


def load_plugins(plugins: List[str]) -> None:
    """Loads each plugin once per process (a second load of the same one does nothing): a C++
    plugin (a shared library, .so: atrous.load_plugin), a Python file or a module."""
    import atrous

    for spec in plugins:
        if spec.endswith(".so"):
            try:
                atrous.load_plugin(spec)
            except ValueError as e:
                raise PluginError(str(e)) from None
            continue
        if spec.endswith(".py") or "/" in spec:
            _load_file(spec)
            continue
        try:
            importlib.import_module(spec)
        except Exception as e:
            raise PluginError(f"--plugin {spec}: {type(e).__name__}: {e}") from None
