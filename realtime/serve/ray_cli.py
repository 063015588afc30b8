"""``gesturecast serve --ray``: the live streams of ``serve`` on Ray Serve replicas (docs/scale.md).

Each replica runs today's batched server (:mod:`ray_replica`); Ray Serve's proxy is the one WebSocket
address clients connect to (``--host``/``--port``), its router (:mod:`ray_router`) sends each new stream
to the least-loaded replica, and Ray scales the replicas on active streams and drains one before it stops.
Ray is imported only here, lazily: without ``gesturecast[scale]`` the command fails with one line.
"""

from __future__ import annotations

import argparse
import logging
from collections.abc import Iterator
from contextlib import contextmanager

from gesturecast.arguments import finite_float, int_at_least
from gesturecast.bridges.ws_access import check_exposure
from gesturecast.errors import UserError
from gesturecast.realtime.cli_flags import server_token, settings_from_args
from gesturecast.realtime.run.engine_setup import SessionFactory
from gesturecast.realtime.serve.cli_args import add_serve_arguments, serve_config
from gesturecast.realtime.serve.server import ServeConfig
from gesturecast.settings import Settings

logger = logging.getLogger(__name__)

APP_NAME = "gesturecast"
ROUTE_PREFIX = "/"
ROUTER_PATH = "gesturecast.realtime.serve.ray_router:LeastLoadedRouter"
INSTALL_HINT = "pip install 'gesturecast[scale]'"
DEFAULT_REPLICAS = 2
DEFAULT_REPLICA_CPUS = 1.0
DEFAULT_DRAIN_S = 600.0  # a replica being scaled down waits this long for its running streams to end
REFUSAL_HEADROOM = 4  # connections a full replica still takes in, only to answer them 1013 at once
AUTOSCALE_TARGET_FRACTION = 0.8  # default --target-streams: scale up before replicas are full


def add_ray_arguments(parser: argparse.ArgumentParser) -> None:
    group = parser.add_argument_group("Ray Serve (gesturecast[scale]; docs/scale.md)")
    group.add_argument("--ray", action="store_true", help="run the streams on Ray Serve replicas (--max-streams each)")
    group.add_argument("--ray-address", metavar="ADDRESS",
                       help="join a running Ray cluster (e.g. auto, or HEAD_IP:6379); default: start one here")
    group.add_argument("--replicas", type=int_at_least(1), default=DEFAULT_REPLICAS,
                       help="replicas (the minimum when autoscaling)")
    group.add_argument("--max-replicas", type=int_at_least(1),
                       help="autoscale on active streams between --replicas and this many")
    group.add_argument("--target-streams", type=finite_float(1.0),
                       help=f"active streams per replica that autoscaling aims at (default "
                            f"{AUTOSCALE_TARGET_FRACTION:g} × --max-streams)")
    group.add_argument("--replica-cpus", type=finite_float(0.0), default=DEFAULT_REPLICA_CPUS,
                       help="CPUs Ray reserves per replica")
    group.add_argument("--drain-timeout", type=finite_float(0.0), default=DEFAULT_DRAIN_S, metavar="SECONDS",
                       help="how long a replica being removed waits for its running streams")


def deployment_options(args: argparse.Namespace) -> dict:
    """Ray Serve deployment options for these flags: replica count or autoscaling, capacity, drain, router."""
    options = {
        "max_ongoing_requests": args.max_streams + REFUSAL_HEADROOM,
        "graceful_shutdown_timeout_s": args.drain_timeout,
        "ray_actor_options": {"num_cpus": args.replica_cpus},
        "request_router_config": {"request_router_class": ROUTER_PATH},
    }
    if args.max_replicas is None:
        return options | {"num_replicas": args.replicas}
    if args.max_replicas < args.replicas:
        raise UserError(f"--max-replicas ({args.max_replicas}) is below --replicas ({args.replicas})")
    target = args.target_streams or AUTOSCALE_TARGET_FRACTION * args.max_streams
    return options | {"autoscaling_config": {"min_replicas": args.replicas, "max_replicas": args.max_replicas,
                                             "target_ongoing_requests": target}}


def replica_settings(args: argparse.Namespace) -> tuple[Settings, ServeConfig, str]:
    """What every replica builds its server from, checked here first (bad flags fail in one line): the stream
    defaults, the server options (the token read here: a replica on another node may not have the file), and the
    latency budget L they give (``delay your audio by …``)."""
    if args.max_streams < 1:
        raise UserError(f"--max-streams must be at least 1, got {args.max_streams}")
    if args.port == 0:
        raise UserError("serve --ray needs a fixed --port (Ray Serve's proxy listens on it)")
    token = server_token(args)
    check_exposure(args.host, token)  # the proxy is what listens beyond this machine
    settings = settings_from_args(args)
    factory = SessionFactory(settings)
    factory.generator()  # the model, its look-ahead and the default style checked before Ray starts
    return settings, serve_config(args, token), factory.budget().describe()


def application(args: argparse.Namespace) -> tuple[object, str]:
    """The Ray Serve application for checked ``serve`` flags (UserError naming the extra without Ray) and
    the latency budget's description."""
    try:
        from gesturecast.realtime.serve.ray_replica import replica_application  # imports ray: the optional extra
    except ImportError as error:
        raise UserError(f"serve --ray needs Ray Serve ({error.name} is missing): {INSTALL_HINT}") from None
    options = deployment_options(args)
    settings, config, budget = replica_settings(args)
    return replica_application(settings, config, options), budget


def app_builder(config: dict) -> object:
    """For a ``serve run`` / ``serve deploy`` config: ``args: {flags: [...]}`` holds ``gesturecast serve --ray``
    flags (docs/scale.md); the config's own ``deployments:`` settings override the replica counts."""
    parser = argparse.ArgumentParser(prog="gesturecast serve --ray (serve config)")
    add_serve_arguments(parser)
    add_ray_arguments(parser)
    return application(parser.parse_args([*config.get("flags", []), "--ray"]))[0]


def start_ray(args: argparse.Namespace) -> bool:
    """Join ``--ray-address`` or start a local Ray; True when this process started it (and so stops it)."""
    import ray
    from ray import serve

    from gesturecast.realtime.serve.ray_proxy import install_proxy_callback

    if args.ray_address is None:
        install_proxy_callback()  # the local proxy closes a dead replica's streams with 1012
        ray.init(include_dashboard=False, logging_level=logging.WARNING)
    else:
        ray.init(address=args.ray_address, logging_level=logging.WARNING)
    serve.start(http_options={"host": args.host, "port": args.port})
    return args.ray_address is None


@contextmanager
def ray_serving(args: argparse.Namespace) -> Iterator[str]:
    """Deploy the streams on Ray Serve; yields where clients connect; removes the application on exit."""
    app, budget = application(args)
    import ray
    from ray import serve

    owns_ray = start_ray(args)
    try:
        serve.run(app, name=APP_NAME, route_prefix=ROUTE_PREFIX)
        yield f"{budget}\nstreams: ws://{args.host}:{args.port}/stream/<id> on Ray Serve ({describe(args)})"
    finally:
        serve.delete(APP_NAME)
        if owns_ray:
            serve.shutdown()
            ray.shutdown()


def describe(args: argparse.Namespace) -> str:
    replicas = f"{args.replicas}" if args.max_replicas is None else f"{args.replicas} to {args.max_replicas}"
    return f"{replicas} replicas, at most {args.max_streams} streams each"
