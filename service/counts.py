"""Counts in words: "1 arm", "5 arms"."""

from __future__ import annotations


def counted(count: object, noun: str) -> str:
    """``count`` and ``noun``, the noun plural (an s) unless the count is one."""
    return f"{count} {noun}" if count == 1 else f"{count} {noun}s"
