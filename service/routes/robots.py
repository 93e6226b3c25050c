"""``/v1/robots``: the catalog and the uploads, one robot, URDF uploads and their deletion, and
the arm as a stick figure for drawing."""

from __future__ import annotations

from typing import cast

import numpy as np
from fastapi import APIRouter, Response
from starlette.concurrency import run_in_threadpool

from toptraj import robots
from toptraj.planners.kinematics.skeleton import skeleton
from toptraj.robots.limits import LIMIT_KINDS
from toptraj.robots.upload_options import upload_options
from toptraj.service.problem_docs import problem_responses
from toptraj.service.problems import RequestRefused
from toptraj.service.schemas.robots import (
    PayloadPublic,
    RobotCreate,
    RobotLimits,
    RobotLimitSources,
    RobotPublic,
    RobotSummary,
    SkeletonPublic,
    SkeletonRequest,
    Source,
)
from toptraj.service.strict_routes import StrictJSONRoute

router = APIRouter(prefix="/v1/robots", tags=["robots"], route_class=StrictJSONRoute)


def _problem(status: int, description: str) -> dict:
    """An error answer as the OpenAPI declares it: an ``application/problem+json`` body."""
    return {**problem_responses(status)[status], "description": description}


def robot_public(robot: robots.Robot) -> RobotPublic:
    """The public description of ``robot``."""
    return RobotPublic(
        name=robot.name,
        dof=robot.dof,
        source=robot.source,
        joint_names=list(robot.joint_names),
        end_effector=robot.end_effector,
        limits=RobotLimits(**robot.limits.as_lists()),
        limit_sources=RobotLimitSources(**{kind: list(robot.limit_sources.get(kind, ())) for kind in LIMIT_KINDS}),
        locked_joints=robot.locked_joints,
        notes=list(robot.notes),
        payload=None if robot.payload is None else PayloadPublic(
            mass=robot.payload.mass,
            center_of_mass=list(robot.payload.center_of_mass),
            inertia=np.reshape(robot.payload.inertia, (3, 3)).tolist(),
            frame=robot.payload.frame or robot.end_effector,
            radius=robot.payload.radius,
        ),
    )


@router.get("", summary="List the robots")
def list_robots() -> list[RobotSummary]:
    """Every robot the service can plan for: the bundled paper arms, the fixed-base arms of
    example-robot-data and the uploaded URDFs.
    \f
    Uploads are listed from the store, without building their models."""
    catalog = [
        RobotSummary(name=robot.name, dof=robot.dof, source=cast(Source, robot.source))
        for robot in map(robots.load, robots.catalog_names())
    ]
    uploads = [RobotSummary(name=upload.name, dof=upload.dof, source="upload") for upload in robots.list_uploads()]
    return catalog + uploads


@router.get("/{name}", summary="Describe one robot", responses={404: _problem(404, "No robot has that name.")})
def get_robot(name: str) -> RobotPublic:
    """Joints, end effector and limits of robot ``name``."""
    return robot_public(robots.load(name))


@router.post(
    "",
    status_code=201,
    summary="Upload a URDF",
    responses={
        409: _problem(409, "The name is taken (a catalog robot, or an upload of a different URDF), or the store is full."),
        413: _problem(413, "The request body is too large."),
        422: _problem(422, "The URDF or the name is invalid; the detail names the link or joint and the reason."),
        503: _problem(503, "The upload store cannot be written (the server's data directory)."),
    },
)
async def upload_robot(body: RobotCreate) -> RobotPublic:
    """Check a fixed-base arm's URDF (tree structure, finite and physically possible masses,
    inertias, origins and limits), build it with Pinocchio and store it durably under ``name``
    (default: a content hash), with its options: joints locked at a value (``locked_joints``)
    limits in MoveIt's ``joint_limits.yaml`` form (``joint_limits``) and the pairs of links allowed
    to touch (``allowed_collisions``, an SRDF or a list of pairs). Uploading the same
    URDF with the same options under the same name again is harmless. The answer says where
    each limit comes from and what was not used (``limit_sources``, ``notes``)."""
    robot = await run_in_threadpool(_register, body)
    return robot_public(robot)


def _register(body: RobotCreate) -> robots.Robot:
    """Read the options (YAML within its bounds) and store the upload: in a worker thread, so
    that neither the parse nor the build holds the event loop."""
    options = upload_options(
        body.locked_joints, body.joint_limits, None if body.payload is None else body.payload.payload(), body.allowed_collisions
    )
    return robots.register_urdf(body.urdf, body.name, options)


@router.delete(
    "/{name}",
    status_code=204,
    summary="Delete an uploaded robot",
    response_class=Response,
    responses={
        404: _problem(404, "No uploaded robot has that name."),
        409: _problem(409, "The robot belongs to the catalog, which cannot be deleted."),
        503: _problem(503, "The upload store cannot be written (the server's data directory)."),
    },
)
def delete_robot(name: str) -> Response:
    """Remove the upload ``name`` from the store; planning for it answers 404 afterwards. Catalog
    robots cannot be deleted (409)."""
    robots.delete_upload(name)
    return Response(status_code=204)


@router.post(
    "/{name}/skeleton",
    summary="Joint positions for drawing",
    responses={404: _problem(404, "No robot has that name."), 422: _problem(422, "Rows of the wrong length, or not finite.")},
)
def robot_skeleton(name: str, body: SkeletonRequest) -> SkeletonPublic:
    """The world positions (m) of the joint origins and the end effector of robot ``name`` in
    each configuration of ``q``: the arm as a stick figure, for stroboscopic pictures; with a
    ``mounting``, its base placed in the world."""
    robot = robots.load(name)
    if body.mounting is not None:
        robot = robots.equip(robot, mounting=body.mounting.mounting())
    wrong = next((k for k, row in enumerate(body.q) if len(row) != robot.dof), None)
    if wrong is not None:
        raise RequestRefused(
            f"q[{wrong}] holds {len(body.q[wrong])} values; each row of q must hold {robot.dof}, one per joint of {name} "
            f"({', '.join(robot.joint_names)})"
        )
    q = np.array(body.q, dtype=float)
    if not np.all(np.isfinite(q)):
        row, joint = np.argwhere(~np.isfinite(q))[0]
        raise RequestRefused(f"q[{row}][{joint}] is not a finite number")
    points, positions = skeleton(robot, q)
    return SkeletonPublic(points=points, positions=positions.tolist())
