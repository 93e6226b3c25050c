"""The web page at ``/``: plan a motion in the browser and look at it (phase plane, joint
curves against their limits, the arm stroboscopically). Static files only, served by the
service itself with Plotly's JavaScript from the installed ``plotly`` wheel: no CDN, no internet."""

from pathlib import Path

STATIC = Path(__file__).parent / "static"
#: The documentation site built from docs/ (``make guide``; git-ignored), served at /guide/.
GUIDE = Path(__file__).parent / "guide"
