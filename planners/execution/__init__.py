"""How a computation runs: its deadline and leash (``deadline``), a worker process for the
solver calls that cannot be interrupted (``isolated``), and the thread count of the numeric
libraries (``threads``)."""
