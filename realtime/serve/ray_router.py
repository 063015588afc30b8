"""Ray Serve request router for live streams: every new stream goes to the least-loaded replica.

Ray's default router asks two random replicas for their queue length ("power of two choices"); with more
than two replicas that is not the least-loaded one. A stream holds its replica for its whole life (one
WebSocket = one ongoing request), so this router probes **every** replica and Ray picks the one with the
fewest ongoing requests among those that accept (below ``max_ongoing_requests``). Ray loads this module by
its import path (:data:`gesturecast.realtime.serve.ray_app.ROUTER_PATH`); it needs ``gesturecast[scale]``.
"""

from __future__ import annotations

from ray.serve.request_router import FIFOMixin, PendingRequest, RequestRouter, RunningReplica


class LeastLoadedRouter(FIFOMixin, RequestRouter):
    """All replicas are candidates of one rank: Ray probes them and takes the shortest queue."""

    async def choose_replicas(self, candidate_replicas: list[RunningReplica],
                              pending_request: PendingRequest | None = None) -> list[list[RunningReplica]]:
        return [list(candidate_replicas)] if candidate_replicas else []
