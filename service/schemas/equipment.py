"""Schemas of what a robot carries (``payload``) and how it is mounted (``mounting``), beside
``robot`` in a trajectory or comparison request; an upload may give a default payload. The rules
(ranges, a physical inertia, a rotation) are ``toptraj.robots.equipment``'s, checked here so that
a 422 names the field."""

from __future__ import annotations

from typing import Annotated

from pydantic import Discriminator, Field, Tag, field_validator, model_validator

from toptraj.robots import equipment
from toptraj.robots.ranges import BASE_POSITION, CENTER_OF_MASS, GRAVITY, PAYLOAD_INERTIA, PAYLOAD_MASS, PAYLOAD_RADIUS
from toptraj.service.schemas.common import Schema, bounded, signed

_Vector3 = Annotated[list[float], Field(min_length=3, max_length=3)]
_Row = Annotated[list[float], Field(min_length=3, max_length=3)]
#: A base's position (m), each coordinate within ``BASE_POSITION``; its orientation (a
#: quaternion, checked by ``checked_orientation``) and rotation matrix (``checked_rotation``):
#: the forms a trajectory's ``mounting`` and a cell arm's ``base`` share.
BasePosition = Annotated[list[Annotated[float, signed(BASE_POSITION)]], Field(min_length=3, max_length=3)]
Quaternion = Annotated[list[float], Field(min_length=4, max_length=4)]
RotationMatrix = Annotated[list[_Row], Field(min_length=3, max_length=3)]


def _checked(check, *args, **kwargs):
    """``check(*args, **kwargs)``, its ``InvalidEquipment`` as the ``ValueError`` pydantic reports
    at the field being validated."""
    try:
        return check(*args, **kwargs)
    except equipment.InvalidEquipment as error:
        raise ValueError(error.detail) from None


def checked_orientation(cls, value):
    """A base's ``orientation`` field: a unit quaternion (``equipment.rotation_matrix``'s rule)."""
    if value is not None:
        _checked(equipment.rotation_matrix, orientation=value)
    return value


def checked_rotation(cls, value):
    """A base's ``rotation`` field: a rotation matrix (``equipment.rotation_matrix``'s rule)."""
    if value is not None:
        _checked(equipment.rotation_matrix, rotation=value)
    return value


def _inertia_shape(value: object) -> str | None:
    """Which form of an inertia ``value`` is: ``"values"`` (a list of 6), ``"matrix"`` (a list of
    3 rows) or ``None`` (neither, three numbers among them: a 422 saying both forms)."""
    if isinstance(value, list | tuple):
        if len(value) == 3 and not any(isinstance(item, list | tuple) for item in value):
            return None  # three numbers: principal moments, neither form
        return {6: "values", 3: "matrix"}.get(len(value))
    return None


#: A payload's inertia: 6 values or 3 rows of 3, told apart by their count (so that a 422 names
#: the one form meant, not each form's failures).
_Inertia = Annotated[
    Annotated[list[Annotated[float, signed(PAYLOAD_INERTIA)]], Field(min_length=6, max_length=6), Tag("values")]
    | Annotated[list[_Row], Field(min_length=3, max_length=3), Tag("matrix")],
    Discriminator(
        _inertia_shape,
        custom_error_type="inertia_shape",
        custom_error_message="give 6 values [Ixx, Iyy, Izz, Ixy, Ixz, Iyz] or a 3x3 matrix (3 rows of 3), in kg m^2 "
        "(principal moments [a, b, c] about the centre of mass are [a, b, c, 0, 0, 0])",
    ),
]


class PayloadRequest(Schema):
    """A rigid body held at the tool: its mass, centre of mass and, optionally, rotational
    inertia. Torques, torque limits and `tau` include it."""

    mass: Annotated[float, bounded(PAYLOAD_MASS)] = Field(description="Mass (kg); 0 is no payload.")
    center_of_mass: Annotated[list[Annotated[float, signed(CENTER_OF_MASS)]], Field(min_length=3, max_length=3)] = Field(
        default=[0.0, 0.0, 0.0], description="Centre of mass [x, y, z] (m) in the payload's frame."
    )
    inertia: _Inertia | None = Field(
        default=None,
        description="Rotational inertia about the centre of mass in the frame's axes (kg m^2): 6 values "
        "[Ixx, Iyy, Izz, Ixy, Ixz, Iyz] or a symmetric 3x3 matrix, positive definite, its principal moments "
        "each at most the sum of the other two; left out, a point mass.",
    )
    frame: Annotated[str, Field(max_length=256)] | None = Field(
        default=None, description="Frame holding the payload (its centre of mass and inertia are in it); default the robot's end effector."
    )
    radius: Annotated[float, bounded(PAYLOAD_RADIUS)] = Field(
        default=0.0,
        description="Radius (m) of a sphere about the centre of mass that is kept from the obstacles, the other arms of a "
        "cell and the robot's own links (path.self_collision, the search) like a link; 0: the payload does not collide.",
    )

    @field_validator("inertia")
    @classmethod
    def _physical(cls, value):
        if value is not None:
            _checked(equipment.inertia_matrix, value)
        return value

    def payload(self) -> equipment.Payload:
        """The library's ``Payload``."""
        return equipment.payload(self.mass, self.center_of_mass, self.inertia, self.frame, self.radius)


class MountingRequest(Schema):
    """The robot's base in the world (floor, wall or ceiling mounting) and the world's gravity.
    Obstacles, Cartesian positions and poses are then in the world frame; torques follow the
    gravity as the base feels it."""

    position: BasePosition = Field(default=[0.0, 0.0, 0.0], description="The base frame's origin [x, y, z] in the world (m).")
    orientation: Quaternion | None = Field(
        default=None,
        description="The base frame's orientation in the world as a unit quaternion [qx, qy, qz, qw] (norm 1 "
        "within 1e-3); a ceiling mount is [1, 0, 0, 0]. Give this or rotation; default the identity.",
    )
    rotation: RotationMatrix | None = Field(
        default=None,
        description="The base frame's orientation as a 3x3 rotation matrix, base axes to world axes (orthonormal "
        "within 1e-3, then made exact; determinant +1). Give this or orientation.",
    )
    gravity: Annotated[list[Annotated[float, signed(GRAVITY)]], Field(min_length=3, max_length=3)] | None = Field(
        default=None, description="Gravity in the world (m/s^2); default the robot's own, [0, 0, -9.81] for the catalog arms."
    )

    check_orientation = field_validator("orientation")(checked_orientation)
    check_rotation = field_validator("rotation")(checked_rotation)

    @model_validator(mode="after")
    def _one_rotation(self):
        if self.orientation is not None and self.rotation is not None:
            raise ValueError("give mounting.orientation or mounting.rotation, not both")
        return self

    def mounting(self) -> equipment.Mounting:
        """The library's ``Mounting``."""
        return equipment.mounting(self.position, self.rotation, self.orientation, self.gravity)


PAYLOAD = Field(
    default=None,
    description="What the robot carries at its tool (mass, centre of mass, inertia): torques, torque limits, "
    "`tau` and peak utilization include it; default the upload's payload, else none.",
)
MOUNTING = Field(
    default=None,
    description="The base pose in the world and the world's gravity; default the base at the world's origin.",
)
