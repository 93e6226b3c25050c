"""The constraints along a path: the rows a, b, c of every limit on the path parameter's
acceleration and speed squared at each grid point (``path_constraints`` with its compiled
assembly), the admissible set they leave (``admissible``: the maximum velocity curve, with
its compiled bounds), the tool-speed limit and the torque rows' interpolation between grid
points."""
