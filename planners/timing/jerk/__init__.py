"""The jerk-limited timing along a given path (Lee, Bylard, Sun & Sentis 2024): the method,
its linear programs, the double-S closed form of straight lines, the polish into segments
of constant jerk, the dense scaling it returns and the estimate of its gap."""
