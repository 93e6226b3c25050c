"""What to write instead of a value the schema refuses, added to pydantic's errors before the
service words them (``toptraj.service.problems.validation_errors``):

* a name outside its choices (``timing.method`` ``"topra"``, ``path.kind`` ``"waypoint"``): the
  allowed name it was most likely meant as (``toptraj.service.field_hints.closest``: the same
  but for case, else the closest by difflib), so that the suggestion is one that works;
* a number sent as a string (``"dt": "0.01"``): that a string was given, and to drop the quotes
  when the number is finite (JSON has no NaN or infinity, which the service refuses anyway);
* a value that fits none of a union's members (``joint_limits: 5``): one error saying what is
  accepted, instead of one per member under pydantic's member names (``joint_limits.str``);
* the same shape refused in every item of a list (a flat ``q`` where rows are expected): one
  error saying the expected shape, instead of one per item.
"""

from __future__ import annotations

import math
import re
import typing
from collections.abc import Mapping
from typing import Any

from toptraj.service.field_hints import closest
from toptraj.service.schemas.trajectories import PathRequest

#: What a union member pydantic names in a location accepts, by the member's name.
_KINDS = {"str": "a string", "int": "an integer", "float": "a number", "bool": "true or false", "dict": "an object", "list": "a list"}
#: pydantic's name of a union member of a plain type: ``str``, ``dict[str,any]``, ``list[float]``.
_MEMBER = re.compile(r"^(str|int|float|bool|dict|list)(\[.*\])?$")
#: JSON's names of Python's values, for "got ...".
_JSON_KIND = {str: "a string", int: "a number", float: "a number", bool: "a boolean", dict: "an object", list: "a list", type(None): "null"}
#: Types of the errors of an item of the wrong shape (a number where a row goes), the same for
#: every item of its list, so said once; a value's own refusal (a range) is said per item.
_SHAPE_TYPES = ("list_type", "dict_type", "model_type")
#: Types of the errors of a number given in another form.
_NUMBER_TYPES = ("float_type", "int_type", "float_parsing", "int_parsing")


def _path_kinds() -> tuple[str, ...]:
    """The ``kind`` of each path schema of ``PathRequest`` (its union's members, each with a
    ``Literal`` kind): ``("waypoints", "cartesian", "free")``."""
    members = typing.get_args(typing.get_args(PathRequest)[0])
    return tuple(kind for member in members for kind in typing.get_args(typing.get_args(member)[0].model_fields["kind"].annotation))


#: The path kinds a request may name, from the schema.
PATH_KINDS = _path_kinds()


def _got(value: Any) -> str:
    return _JSON_KIND.get(type(value), type(value).__name__)


def value_hint(item: Mapping[str, Any]) -> str:
    """A clause to add to pydantic's message of error ``item``: the nearest allowed choice, or
    what to change in a number sent as a string; "" when there is nothing to add."""
    value, kind = item.get("input"), item.get("type")
    if not isinstance(value, str) or len(value) > 60:
        return ""
    if kind == "literal_error":
        close = closest(value, re.findall(r"'([^']*)'", str((item.get("ctx") or {}).get("expected", ""))))
        return f": did you mean {close!r}?" if close else ""
    if kind in _NUMBER_TYPES:
        try:
            finite = math.isfinite(float(value))
        except ValueError:
            finite = False
        return f"; got the string {value!r}" + ("; write the number without quotes" if finite else "")
    return ""


def _path_kind(item: Mapping[str, Any]) -> Mapping[str, Any]:
    """The error of an unknown ``path.kind`` at ``path.kind`` (pydantic places it at ``path``),
    with the kind given and the nearest allowed one."""
    value = item.get("input")
    kind = value.get("kind") if isinstance(value, dict) else None
    if not isinstance(kind, str):
        return item
    message = item["msg"] + (f", not {kind[:60]!r}" if len(kind) <= 60 else "")
    close = closest(kind, PATH_KINDS)
    return {**item, "loc": (*item["loc"], "kind"), "msg": message + (f": did you mean {close!r}?" if close else ""), "input": kind}


def collapsed(items: list[Mapping[str, Any]]) -> list[dict[str, Any]]:
    """``items`` (pydantic's ``errors()``) with the errors of one value that fits no member of
    a union made one, saying what is accepted, and the same error of every item of a list of
    more than one made one, saying the expected shape."""
    out: list[dict[str, Any]] = []
    for item in items:
        item = _path_kind(item) if item.get("type") == "path_kind" else item
        loc = tuple(item["loc"])
        last = out[-1] if out else None
        if loc and isinstance(loc[-1], str) and _MEMBER.match(loc[-1]):
            if last is not None and last.get("members") and tuple(last["loc"]) == loc[:-1]:
                last["members"].append(loc[-1])
                continue
            out.append({**item, "loc": loc[:-1], "members": [loc[-1]], "items": []})
            continue
        if (
            last is not None
            and loc and isinstance(loc[-1], int)
            and tuple(last["loc"])[:-1] == loc[:-1]
            and last.get("type") == item.get("type") in _SHAPE_TYPES
            and _kind(last.get("input")) == _kind(item.get("input"))
        ):
            last["items"].append(loc[-1])
            continue
        out.append({**item, "items": [loc[-1]] if loc and isinstance(loc[-1], int) else []})
    return [_worded(item) for item in out]


def _kind(value: object) -> str:
    """What a value is for merging the same error of a list's items: a number (int or float
    alike: a flat list of waypoints mixes them), else its type's name."""
    return "number" if isinstance(value, int | float) and not isinstance(value, bool) else type(value).__name__


def _worded(item: dict) -> dict:
    """An error made of several (``collapsed``) as one sentence."""
    if "members" in item:
        kinds = list(dict.fromkeys(_KINDS[name.partition("[")[0]] for name in item.pop("members")))
        if len(kinds) > 1:
            accepted = ", ".join(kinds[:-1]) + " or " + kinds[-1]
            return {**item, "type": "union", "msg": f"should be {accepted}; got {_got(item.get('input'))}"}
    indices = item.pop("items", [])
    if len(indices) > 1:
        loc = tuple(item["loc"])
        if item.get("type") == "list_type" and isinstance(item.get("input"), int | float):
            message = (
                "should be a list of lists (one list of values per item, e.g. [[0, 0], [1, 1]]); got a flat list of numbers: "
                "put each item's values in brackets of their own"
            )
        else:
            shown = ", ".join(f"[{index}]" for index in indices[:5]) + (", ..." if len(indices) > 5 else "")
            message = f"{item['msg']} (items {shown}: {len(indices)} of them)"
        return {**item, "loc": loc[:-1], "type": "items", "msg": message}
    return item
