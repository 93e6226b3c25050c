"""The runner: a problem solved by its method of either family (``run``), a given path timed
stretch by stretch between its corners (``given_path``), the answer built the same way for every
method (``answer``), the method a request names (``choice``), and the accuracy policy every grid
method's answer follows (``accuracy``)."""
