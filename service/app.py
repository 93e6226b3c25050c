"""``create_app()``: the FastAPI application (public contract)."""

from __future__ import annotations

import logging
import os
from contextlib import asynccontextmanager

from fastapi import FastAPI
from fastapi_offline import FastAPIOffline
from starlette.concurrency import run_in_threadpool

from toptraj import robots
from toptraj.planners.execution.isolated import start_worker_server
from toptraj.planners.execution.threads import single_blas_thread
from toptraj.service import stopping, warmup
from toptraj.service.body_limit import BodySizeLimit
from toptraj.service.errors import UnexpectedErrors, install_problem_handlers
from toptraj.service.finite import FiniteJSONResponse
from toptraj.service.jobs import JOB_MODULES, job_runner
from toptraj.service.offline_pages import OwnImagesOnly
from toptraj.service.routes import batches, cells, guide, health, jobs, trajectories, web
from toptraj.service.routes import robots as robot_routes
from toptraj.service.serving import open_connections
from toptraj.service.settings import Settings
from toptraj.service.workers import PlanningWorkers

#: Seconds a 503 of the heavy plannings' lane asks to wait: each holds its worker for seconds.
HEAVY_RETRY_AFTER_S = 5
#: Where a server process says what it does while it starts (uvicorn's own log).
_log = logging.getLogger("uvicorn.error")


def _warm_up() -> None:
    """Build every catalog robot and load the compiled phase-plane and conditioning kernels
    once (``toptraj.service.warmup.server_steps``), each step logged, so that first requests are fast.
    The solver stacks of the other methods are imported where those run, when they first do."""
    process = os.getpid()
    warmup.run_steps(warmup.server_steps(), lambda line: _log.info("toptraj start-up [%d]: %s", process, line))


#: FastAPI's telemetry options with every part off (``Settings.telemetry``).
_NO_TELEMETRY = {"tracing": False, "metrics": False, "logs": False, "operation_spans": False}


def create_app(settings: Settings | None = None) -> FastAPI:
    """The toptraj HTTP service. Its settings also choose where this process keeps uploads
    (``robots.configure_uploads``): one upload store per process, the last app's."""
    warmup.imports_done()
    settings = settings or Settings()
    single_blas_thread()  # plannings run side by side; see toptraj.planners.execution.threads
    robots.configure_uploads(
        settings.data_dir,
        max_uploads=settings.max_uploads,
        max_bytes=settings.max_upload_bytes,
        cache_size=settings.upload_cache_size,
    )

    @asynccontextmanager
    async def lifespan(app: FastAPI):
        if settings.preload_robots:
            await run_in_threadpool(_warm_up)
        # After the warm-up: the fork server's imports (its own process) then do not compete
        # for the cores with this process's, and it is ready a second or two after this one.
        await run_in_threadpool(start_worker_server, JOB_MODULES)
        await run_in_threadpool(app.state.jobs.start)
        stopping.serving()  # a stop is graceful from here on
        yield
        # Running plannings end at their next deadline check; an app started again (as test
        # clients do, even overlapping) gets fresh threads under the same slots.
        app.state.planning.close()
        app.state.heavy_planning.close()
        app.state.jobs.stop_running()
        stopping.stopped()  # in a server process: its fork server too, which may still be importing
        await run_in_threadpool(app.state.jobs.close)

    # /docs and /redoc with Swagger UI's and ReDoc's scripts from the installed fastapi-offline
    # wheel, not a CDN: robot cells are often offline.
    app = FastAPIOffline(
        title="toptraj",
        summary="Time-optimal trajectories with torques for URDF robot arms.",
        description="The guide: [/guide/](/guide/) (concepts, methods, errors, jobs, the Python client). The web page: [/](/).",
        version="0.1.0",
        lifespan=lifespan,
        default_response_class=FiniteJSONResponse,
        telemetry=None if settings.telemetry else _NO_TELEMETRY,
    )
    app.state.settings = settings
    app.state.planning = PlanningWorkers(settings.plan_workers, settings.plan_queue, settings.plan_leash_s, open_connections)
    app.state.heavy_planning = PlanningWorkers(settings.plan_heavy_workers, settings.plan_heavy_queue, label="heavy planning", retry_after=HEAVY_RETRY_AFTER_S)
    app.state.jobs = job_runner(settings)
    install_problem_handlers(app)
    app.add_middleware(BodySizeLimit, max_bytes=settings.max_body_bytes)
    app.add_middleware(OwnImagesOnly)
    app.add_middleware(UnexpectedErrors)  # last added, so outermost
    app.include_router(health.router)
    app.include_router(robot_routes.router)
    app.include_router(trajectories.router)
    app.include_router(cells.router)
    app.include_router(jobs.router)
    app.include_router(batches.router)
    app.include_router(web.router)
    app.include_router(guide.router)
    return app
