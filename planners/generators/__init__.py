"""Motion generators: methods that find the motion itself, path and timing together (via
points, unsynchronized joint moves, free-path collocation, the global search among
obstacles)."""
