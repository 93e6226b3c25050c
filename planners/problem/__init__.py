"""The planning problem, built and validated once (``build``) into a ``Problem`` (``problem``):
the request's timing options and paths (``requests``, ``free_motion``), the waypoints' checks and
spline (``waypoints``), boundary states, the ranges of numeric inputs, the checks of a built path
(``path_checks``), and the interface of the motion generators (``methods``)."""
