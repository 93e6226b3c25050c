"""The pipeline that runs a method on a problem: a given path timed stretch by stretch
between its corners (``given_path``), free motions re-timed (``timed_free``), and the
accuracy policy every grid method's answer follows (``accuracy``)."""
