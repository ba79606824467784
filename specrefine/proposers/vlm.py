"""The VLM proposer: asks a vision-language model (through a :class:`~specrefine.vlm.VLMClient`).

A bad reply is logged, re-asked once and dropped; it never ends a run.
"""

from __future__ import annotations

import logging
from collections.abc import Sequence

from ..core.errors import ProposalRejected
from ..core.graph import TaskGraph
from ..core.regions import Region
from ..vlm import BadReply, ReplayClient, VLMClient
from .base import CandidateFeedback, EdgeQuery, GraphFeedback, GraphQuery, Proposer, _jsonable
from .prompts import graph_messages, render_prompt, split_messages
from .schema import parse_graph, parse_split

log = logging.getLogger(__name__)


class VLMProposer(Proposer):
    """Asks a vision-language model (through a :class:`~specrefine.vlm.VLMClient`)."""

    is_vlm = True
    sees_images = True

    def __init__(self, client: VLMClient, *, spec: str | None = None, reask: bool = True, max_waypoints: int = 32):
        super().__init__(spec or client.name)
        self.client = client
        self.name = client.name if not isinstance(client, ReplayClient) else f"{client.name} (recorded {client.model})"
        self.reask = reask
        self.max_waypoints = max_waypoints
        self.last_messages: list[dict] | None = None  # the latest request (see vlm.messages_to_text)

    @property
    def calls(self) -> int:
        return self.client.calls

    @property
    def cost_usd(self) -> float:
        return self.client.cost_usd

    @property
    def proposer_calls(self) -> int:
        return self.client.calls

    @property
    def bad_replies(self) -> int:
        """Answers the client could not read (no chat completion, no choices, too long)."""
        return self.client.bad_replies

    def split(self, q: EdgeQuery, w: int, feedback: Sequence[CandidateFeedback] = ()) -> list[list[Region]]:
        messages = split_messages(q, feedback)
        parse = lambda text: parse_split(text, q.maze, max_waypoints=self.max_waypoints, snap=q.snap)  # noqa: E731
        return self._ask(messages, w, parse, "edge split", round_=1 + bool(feedback))

    def graph(self, q: GraphQuery, w: int, feedback: Sequence[GraphFeedback] = ()) -> list[TaskGraph]:
        messages = graph_messages(q, feedback)
        parse = lambda text: parse_graph(text, q.maze, q.graph)  # noqa: E731
        return self._ask(messages, w, parse, "task graph", round_=1 + bool(feedback))

    def _ask(self, messages, w, parse, kind, round_):
        entry = {"kind": kind, "round": round_, "accepted": [], "rejected": [], "reasked": False}
        self.history.append(entry)
        self.last_messages = messages
        texts = self.client.complete(messages, n=w)
        out, bad = self._parse_all(texts, parse, entry, kind)
        if bad and self.reask:
            entry["reasked"] = True
            reasons = "\n".join(f"- answer {i}: {why}" for i, (_, why) in enumerate(bad, start=1))
            follow = messages + [
                {"role": "assistant", "content": bad[0][0] or "(empty reply)"},
                {"role": "user", "content": render_prompt("reask", count=f"{len(bad)} of {len(texts)}",
                                                          reasons=reasons, schema_name=kind)},
            ]
            more, _ = self._parse_all(self.client.complete(follow, n=len(bad)), parse, entry, kind)
            out += more
        return out[:w]

    def _parse_all(self, texts, parse, entry, kind):
        good, bad = [], []
        for text in texts:
            if isinstance(text, BadReply):  # the client could not read it (and has warned)
                entry["rejected"].append(text.reason)
                bad.append((text, text.reason))
                continue
            try:
                value, reasoning = parse(text)
            except ProposalRejected as exc:
                log.warning("%s: rejected %s candidate: %s", self.name, kind, exc)
                entry["rejected"].append(str(exc))
                bad.append((text, str(exc)))
                continue
            except Exception as exc:  # noqa: BLE001 - a reply must never end the run
                log.warning("%s: rejected %s candidate (unexpected: %s)", self.name, kind, exc)
                entry["rejected"].append(f"unexpected: {exc}")
                bad.append((text, f"could not be interpreted ({type(exc).__name__})"))
                continue
            good.append(value)
            entry["accepted"].append({"reasoning": reasoning, "value": _jsonable(value)})
        return good, bad
