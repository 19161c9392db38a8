"""A scene given as a dict, written as the TOML text that parse_scene reads.

The scene format is README.md's "Scene format": top-level keys (``units``), tables
(``[body]``, ``[material]``, ``[time]``, nested ``[body.material]``) and arrays of tables
(``[[body]]``, ``[[obstacle]]``, ``[[fixed]]``). A dict value becomes a table, a list of
dicts an array of tables, anything else a value: bool, int, float (``nan`` and ``inf``
included: the scene reader refuses them with its own message), str, and lists of those
(nested lists for ``track_points``). NumPy scalars and arrays are taken by value.
"""
import json
import math
import numbers
import re

__all__ = ["dumps"]

_BARE_KEY = re.compile(r"^[A-Za-z0-9_-]+$")


def _key(k):
    if not isinstance(k, str):
        raise TypeError(f"scene keys must be strings, not {type(k).__name__} ({k!r})")
    return k if _BARE_KEY.match(k) else json.dumps(k)


def _plain(v):
    """NumPy arrays and scalars as Python values."""
    if hasattr(v, "tolist") and not isinstance(v, (str, bytes)):
        return v.tolist()
    return v


def _value(v, where):
    v = _plain(v)
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, numbers.Integral):
        return str(int(v))
    if isinstance(v, numbers.Real):
        x = float(v)
        if math.isnan(x):
            return "nan"
        if math.isinf(x):
            return "inf" if x > 0 else "-inf"
        return repr(x)
    if isinstance(v, str):
        return json.dumps(v)  # a TOML basic string: the same escapes, \uXXXX for the rest
    if isinstance(v, (list, tuple)):
        return "[" + ", ".join(_value(x, where) for x in v) + "]"
    raise TypeError(f"scene {where}: cannot write a {type(v).__name__} as TOML ({v!r})")


def _is_table_array(v):
    v = _plain(v)
    return isinstance(v, (list, tuple)) and len(v) > 0 and all(isinstance(x, dict) for x in v)


def _emit(table, path, out):
    """The plain keys of `table`, then its sub-tables and arrays of tables."""
    for k, v in table.items():
        if not isinstance(v, dict) and not _is_table_array(v):
            out.append(f"{_key(k)} = {_value(v, '.'.join(path + [str(k)]))}")
    for k, v in table.items():
        sub = path + [_key(k)]
        if isinstance(v, dict):
            out.append("")
            out.append("[" + ".".join(sub) + "]")
            _emit(v, sub, out)
        elif _is_table_array(v):
            for item in v:
                out.append("")
                out.append("[[" + ".".join(sub) + "]]")
                _emit(item, sub, out)


def dumps(scene):
    """TOML text of a scene dict."""
    if not isinstance(scene, dict):
        raise TypeError(f"a scene dict is expected, not {type(scene).__name__}")
    out = []
    _emit(scene, [], out)
    return "\n".join(out).lstrip("\n") + "\n"
