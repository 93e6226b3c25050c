"""Shared pydantic configuration: reject unknown fields, NaN/inf and numbers outside their
physical range at the edge."""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass

from annotated_types import GroupedMetadata
from pydantic import AfterValidator, BaseModel, ConfigDict, Field, WithJsonSchema
from pydantic_core import PydanticCustomError

from toptraj.planners.problem.ranges import Range


class Schema(BaseModel):
    """Base of every request schema: extra fields, non-finite numbers and values of another JSON
    type (`true` or `"0.1"` for a number) are errors, as the OpenAPI declares. A request is
    read, never changed: frozen, its models are hashable, so pydantic shares a default
    sub-model among requests instead of validating a deep copy of it for each one."""

    model_config = ConfigDict(extra="forbid", allow_inf_nan=False, strict=True, frozen=True)


def _range_error(value: float, shown: str) -> PydanticCustomError:
    return PydanticCustomError(
        "out_of_range", "{value} is not within the accepted range {range}", {"value": f"{value:g}", "range": shown}
    )


@dataclass(frozen=True)
class RangeCheck(GroupedMetadata):
    """``Annotated`` metadata of a float checked against a range: its validator (a 422 naming the
    range) and its OpenAPI minimum and maximum. Made by ``bounded`` and ``signed``."""

    validator: AfterValidator
    schema: WithJsonSchema

    def __iter__(self) -> Iterator[object]:
        yield self.validator
        yield self.schema


def bounded(accepted: Range) -> RangeCheck:
    """A float in [low, high] of ``accepted``: ``Annotated[float, bounded(accepted)]`` (OpenAPI
    minimum and maximum; a 422 naming the range otherwise)."""

    def check(value: float) -> float:
        if not accepted.holds(value):
            raise _range_error(value, accepted.describe())
        return value

    return RangeCheck(
        AfterValidator(check),
        WithJsonSchema({"type": "number", "minimum": accepted.low, "maximum": accepted.high}),
    )


def signed(accepted: Range) -> RangeCheck:
    """A float in [-high, high] of ``accepted``, a signed quantity of bounded magnitude:
    ``Annotated[float, signed(accepted)]``."""
    shown = f"[-{accepted.high:g}, {accepted.high:g}] {accepted.unit}".rstrip()

    def check(value: float) -> float:
        if not accepted.holds_signed(value):
            raise _range_error(value, shown)
        return value

    return RangeCheck(
        AfterValidator(check),
        WithJsonSchema({"type": "number", "minimum": -accepted.high, "maximum": accepted.high}),
    )


class ValidationIssue(BaseModel):
    """One field of a request that failed validation."""

    field: str = Field(description="Where, e.g. `path.waypoints[1][2]`.")
    message: str = Field(description="What is wrong with the field.")


class Problem(BaseModel):
    """An RFC 9457 problem, as every error answer carries it (``application/problem+json``).
    Extension members: ``errors`` (validation failures, one per field), ``s`` and ``joint``
    (where along the path, and which joint, a limit cannot be met)."""

    type: str = Field(default="about:blank", description="A URI naming the kind of problem (about:blank: the status says it).")
    title: str = Field(description="A short summary of the kind of problem.")
    status: int = Field(description="The HTTP status code.")
    detail: str = Field(description="What went wrong, where, and how to fix it.")
    errors: list[ValidationIssue] | None = Field(default=None, description="For a malformed request: each field and what is wrong with it.")
    s: float | None = Field(default=None, description="Path parameter in [0, 1] where planning fails.")
    joint: str | None = Field(default=None, description="Joint whose limit cannot be met.")
    limit: str | None = Field(default=None, description="Kind of limit that cannot be met (velocity, acceleration, torque, jerk).")
