"""The planning problem as the library receives it: the request's timing options and paths
(``requests``), the waypoints' checks and spline (``waypoints``), boundary states and the
ranges of numeric inputs."""
