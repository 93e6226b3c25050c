"""``/v1/robots``: the catalog, one robot, and URDF uploads."""

from __future__ import annotations

from fastapi import APIRouter
from starlette.concurrency import run_in_threadpool

import robots
from service.problems import problem_responses
from service.schemas.robots import RobotCreate, RobotPublic, RobotSummary

router = APIRouter(prefix="/v1/robots", tags=["robots"])


def robot_public(robot: robots.Robot) -> RobotPublic:
    """The public description of ``robot``."""
    return RobotPublic(
        name=robot.name,
        dof=robot.dof,
        source=robot.source,
        joint_names=list(robot.joint_names),
        end_effector=robot.end_effector,
        limits=robot.limits.as_lists(),
    )


@router.get("", summary="List the robots")
def list_robots() -> list[RobotSummary]:
    """Every robot the service can plan for: the bundled paper arms, the fixed-base arms of
    example-robot-data and the uploaded URDFs."""
    return [
        RobotSummary(name=robot.name, dof=robot.dof, source=robot.source)
        for robot in map(robots.load, robots.catalog_names())
    ]


@router.get("/{name}", summary="Describe one robot", responses=problem_responses(404))
def get_robot(name: str) -> RobotPublic:
    """Joints, end effector and limits of robot ``name``."""
    return robot_public(robots.load(name))


@router.post(
    "",
    status_code=201,
    summary="Upload a URDF",
    responses=problem_responses(409),
)
async def upload_robot(body: RobotCreate) -> RobotPublic:
    """Parse a fixed-base arm's URDF with Pinocchio and keep it under ``name`` (default: a
    content hash). Malformed XML, missing inertias or missing/zero limits are refused with 422."""
    robot = await run_in_threadpool(robots.register_urdf, body.urdf, body.name)
    return robot_public(robot)
