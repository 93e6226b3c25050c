"""MkDocs hook: a link to a folder of the repository that the site leaves out (such as
``measures/``, scripts rather than pages) reads as its name in code, so that every other
unrecognized link still fails ``mkdocs build --strict``."""

from __future__ import annotations

import re
from pathlib import Path

_FOLDER_LINK = re.compile(r"\[([^\]]+)\]\(((?:[\w.-]+/)+)\)")


def on_page_markdown(markdown, page, config, files):
    """Replace ``[label](folder/)`` by ``label`` where ``folder/`` holds no page of the site."""
    here = Path(config["docs_dir"]) / Path(page.file.src_path).parent

    def plain(match: re.Match) -> str:
        folder = here / match.group(2)
        if folder.is_dir() and not any(folder.glob("*.md")):
            return match.group(1)
        return match.group(0)

    return _FOLDER_LINK.sub(plain, markdown)
