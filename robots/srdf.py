"""The pairs of links allowed to touch, as an SRDF's ``<disable_collisions link1= link2=/>``
(MoveIt's semantic robot description) or as a list of [link, link] pairs.

What comes from outside is bounded before it is read: at most ``MAX_SRDF_CHARS`` characters,
no ``<!DOCTYPE>`` (no entities to expand), at most ``MAX_ELEMENTS`` elements, ``MAX_DEPTH``
levels and ``MAX_PAIRS`` pairs, link names of at most ``MAX_NAME_CHARS`` characters. Every
other element of an SRDF (groups, end effectors, virtual joints) is ignored.

The catalog's arms of example-robot-data take the SRDF the package ships for them, when it
ships one (``shipped_pairs``).
"""

from __future__ import annotations

import os
from collections.abc import Iterable

from toptraj.robots.errors import ToptrajError, excerpt

#: Largest SRDF text read, in characters (ur5's is 1 kB, a humanoid's 100 kB).
MAX_SRDF_CHARS = 200_000
#: Most elements of an SRDF, at most nesting levels, and most allowed pairs.
MAX_ELEMENTS = 20_000
MAX_DEPTH = 8
MAX_PAIRS = 2_000
#: Longest link name.
MAX_NAME_CHARS = 200


class InvalidCollisionList(ToptrajError):
    """An allowed-collision list (SRDF text or pairs) that is malformed, too large or names an
    unknown link."""

    title = "Invalid allowed-collision list"


def pair(first: str, second: str) -> tuple[str, str]:
    """The pair of link names in a canonical order (sorted)."""
    return (first, second) if first <= second else (second, first)


def _name(value, where: str) -> str:
    if not isinstance(value, str) or not value or len(value) > MAX_NAME_CHARS:
        raise InvalidCollisionList(f"{where} must be a link name of 1 to {MAX_NAME_CHARS} characters, got {excerpt(value, 40)}")
    return value


def srdf_pairs(text: str) -> frozenset[tuple[str, str]]:
    """The ``disable_collisions`` pairs of an SRDF ``text``.

    Raises:
        InvalidCollisionList: text too long, a DOCTYPE, not XML, too many elements or levels or
            pairs, an element without both link names.
    """
    if not isinstance(text, str) or len(text) > MAX_SRDF_CHARS:
        size = f"{len(text)} characters" if isinstance(text, str) else excerpt(text, 40)
        raise InvalidCollisionList(f"the SRDF must be a text of at most {MAX_SRDF_CHARS} characters, got {size}")
    if "<!DOCTYPE" in text.upper() or "<!ENTITY" in text.upper():
        raise InvalidCollisionList("the SRDF must not hold a <!DOCTYPE> or <!ENTITY>: remove it (SRDFs need none)")
    import xml.etree.ElementTree as ElementTree  # here: most plans read no SRDF

    try:
        root = ElementTree.fromstring(text)
    except ElementTree.ParseError as error:
        raise InvalidCollisionList(f"the SRDF is not well-formed XML: {excerpt(str(error), 120)[1:-1]}") from None
    pairs: set[tuple[str, str]] = set()
    stack, count = [(root, 1)], 0
    while stack:
        element, depth = stack.pop()
        count += 1
        if count > MAX_ELEMENTS or depth > MAX_DEPTH:
            raise InvalidCollisionList(
                f"the SRDF holds more than {MAX_ELEMENTS} elements or nests more than {MAX_DEPTH} levels; "
                "give only its <disable_collisions> elements"
            )
        if element.tag == "disable_collisions":
            where = f"the SRDF's disable_collisions #{len(pairs) + 1}"
            pairs.add(pair(_name(element.get("link1"), f"{where} link1"), _name(element.get("link2"), f"{where} link2")))
            if len(pairs) > MAX_PAIRS:
                raise InvalidCollisionList(f"the SRDF disables more than {MAX_PAIRS} pairs")
        stack.extend((child, depth + 1) for child in element)
    return frozenset(pairs)


def allowed_pairs(given: object) -> frozenset[tuple[str, str]]:
    """The allowed pairs of ``given``: SRDF text, or a list of [link, link] pairs.

    Raises:
        InvalidCollisionList: neither form, too many pairs, a pair that is not two names.
    """
    if isinstance(given, str):
        return srdf_pairs(given)
    if not isinstance(given, list | tuple) or len(given) > MAX_PAIRS:
        raise InvalidCollisionList(
            f"allowed_collisions must be an SRDF text or a list of at most {MAX_PAIRS} [link, link] pairs, "
            f"got {excerpt(given, 40)}"
        )
    pairs = set()
    for index, item in enumerate(given):
        if not isinstance(item, list | tuple) or len(item) != 2:
            raise InvalidCollisionList(f"allowed_collisions[{index}] must be a pair [link, link], got {excerpt(item, 40)}")
        first, second = _name(item[0], f"allowed_collisions[{index}][0]"), _name(item[1], f"allowed_collisions[{index}][1]")
        if first == second:
            raise InvalidCollisionList(
                f"allowed_collisions[{index}] pairs link {excerpt(first, 40)} with itself, which is never checked: give two "
                "different links"
            )
        pairs.add(pair(first, second))
    return frozenset(pairs)


def check_links(pairs: Iterable[tuple[str, str]], links: Iterable[str]) -> None:
    """Raise ``InvalidCollisionList`` when a pair names a link that is not among ``links``."""
    known = set(links)
    for first, second in sorted(pairs):
        for name in (first, second):
            if name not in known:
                raise InvalidCollisionList(
                    f"allowed_collisions names link {excerpt(name, 40)}, which is not a link of the robot; its links: "
                    f"{excerpt(', '.join(sorted(known)), 300)}"
                )


def shipped_pairs(loader_name: str) -> frozenset[tuple[str, str]] | None:
    """The ``disable_collisions`` of the SRDF example-robot-data ships for its robot
    ``loader_name``; ``None`` when it ships none."""
    from example_robot_data.robots_loader import ROBOTS
    from example_robot_data.utils import getModelPath

    loader = ROBOTS[loader_name]
    filename = getattr(loader, "srdf_filename", "")
    if not filename:
        return None
    subpath = os.path.join(loader.path, getattr(loader, "srdf_subpath", "srdf"), filename)
    try:
        path = os.path.join(getModelPath(subpath), subpath)
    except OSError:
        return None
    if not os.path.isfile(path):
        return None
    with open(path, encoding="utf-8") as file:
        return srdf_pairs(file.read())
