"""Classical time laws (Angeles ch. 6; the lecture "Trajectory Planning"): the methods, the
normalized profiles and polynomial segments, the timing made of them, and the cubic
splines through supporting points."""
