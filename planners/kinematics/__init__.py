"""Kinematics on top of Pinocchio: inverse kinematics along Cartesian lines, and the kinematic
conditioning of the Jacobian."""
