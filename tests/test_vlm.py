"""The VLM layer over the REAL LiteLLM HTTP path, against an OpenAI-compatible server on 127.0.0.1.

No network: the test starts a stdlib ``http.server`` in a thread, points ``openai/...`` models at
it with ``api_base`` and a dummy key from a monkeypatched environment variable, and scripts its
replies (good, malformed, schema-violating, in a wall, 429, 500, 400, 401, 404).
"""

from __future__ import annotations

import base64
import http.server
import json
import logging
import re
import struct
import threading
import time
import zlib
from pathlib import Path

import numpy as np
import pytest

from specrefine.core.errors import ProposalRejected, ReplayMiss, SpecrefineError, VLMConfigError, VLMUnavailable
from specrefine.core.graph import check_refines
from specrefine.core.mazes import load_maze, parse_maze
from specrefine.core.regions import Disc
from specrefine.core.spec import maze_task
from specrefine.proposers import (
    CandidateFeedback,
    EdgeQuery,
    GraphFeedback,
    GraphQuery,
    VLMProposer,
    make_proposer,
    split_messages,
)
from specrefine.proposers.schema import parse_graph
from specrefine.vlm import LiteLLMClient, ReplayClient, request_hash

KEY = "sk-test-DUMMY-5ecret-0123456789abcdef"
MODEL = "openai/test-model"


def tiny_png(rgb=(255, 0, 0)) -> bytes:
    """A valid 2x2 PNG (no renderer needed)."""
    def chunk(kind, data):
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data) & 0xFFFFFFFF)

    raw = b"".join(b"\x00" + bytes(rgb) * 2 for _ in range(2))
    return (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", 2, 2, 8, 2, 0, 0, 0))
            + chunk(b"IDAT", zlib.compress(raw)) + chunk(b"IEND", b""))


# replies for the split-doorway maze (point scale: x in [-6.5, 6.5], y in [-5, 5])
GOOD = json.dumps({"reasoning": "go through the lower doorway",
                   "waypoints": [{"type": "disc", "center": [-1.0, -2.5], "radius": 0.4},
                                 {"type": "disc", "center": [1.0, -2.5], "radius": 0.4}]})
GOOD2 = json.dumps({"waypoints": [{"type": "box", "min": [-1.4, -2.9], "max": [-0.6, -2.1]}]})
GOOD3 = "Sure! ```json\n" + json.dumps({"waypoints": [{"type": "disc", "center": [0.0, 2.5], "radius": 0.3}]}) + "\n```"
MALFORMED = '{"waypoints": [{"type": "disc", "center": [1, 2], '
SCHEMA_BAD = json.dumps({"waypoints": [{"type": "disc", "center": [1.0], "radius": 0.4}]})
IN_WALL = json.dumps({"waypoints": [{"type": "disc", "center": [0.0, 0.0], "radius": 0.4}]})  # cell (5, 6) is '#'


class Server:
    """Scripted OpenAI-compatible chat-completions endpoint."""

    def __init__(self):
        # items: int (HTTP error status), (status, {header: value}), list[str] (choice contents) or bytes (a raw
        # HTTP 200 body)
        self.script: list = []
        self.requests: list[dict] = []
        outer = self

        class Handler(http.server.BaseHTTPRequestHandler):
            def do_POST(self):
                body = json.loads(self.rfile.read(int(self.headers["Content-Length"])))
                headers = {k.lower(): v for k, v in self.headers.items()}  # HTTP names are case-insensitive
                outer.requests.append({"path": self.path, "headers": headers, "body": body})
                item = outer.script.pop(0) if outer.script else [GOOD]
                status, headers = item if isinstance(item, tuple) else (item, {})
                if isinstance(status, int):
                    data = json.dumps({"error": {"message": f"scripted {status}", "type": "test"}}).encode()
                    self.send_response(status)
                elif isinstance(item, bytes):
                    data = item
                    self.send_response(200)
                else:
                    n = int(body.get("n") or 1)
                    contents = (item * n)[:n] if len(item) < n else item[:n]
                    data = json.dumps({
                        "id": f"chatcmpl-{len(outer.requests)}", "object": "chat.completion", "created": 0,
                        "model": body["model"],
                        "choices": [{"index": i, "finish_reason": "stop",
                                     "message": {"role": "assistant", "content": c}} for i, c in enumerate(contents)],
                        "usage": {"prompt_tokens": 1000, "completion_tokens": 100, "total_tokens": 1100},
                    }).encode()
                    self.send_response(200)
                for name, value in {"Content-Type": "application/json", **headers}.items():
                    self.send_header(name, value)
                self.send_header("Content-Length", str(len(data)))
                self.end_headers()
                self.wfile.write(data)

            def log_message(self, *args):
                pass

        self.httpd = http.server.ThreadingHTTPServer(("127.0.0.1", 0), Handler)
        self.base = f"http://127.0.0.1:{self.httpd.server_port}/v1"
        self.thread = threading.Thread(target=self.httpd.serve_forever, daemon=True)
        self.thread.start()

    def close(self):
        self.httpd.shutdown()
        self.httpd.server_close()


@pytest.fixture(scope="module")
def server():
    s = Server()
    yield s
    s.close()


@pytest.fixture
def srv(server, monkeypatch):
    server.script.clear()
    server.requests.clear()
    monkeypatch.setenv("OPENAI_API_KEY", KEY)
    return server


@pytest.fixture(scope="module")
def maze():
    return load_maze("split_doorway")


@pytest.fixture
def query(maze):
    return EdgeQuery(maze, "point", maze.start, maze.goal, maze.walls, success=0.3125, n=32, image_png=tiny_png())


def proposer(srv, tmp_path, **kw) -> VLMProposer:
    client = LiteLLMClient(kw.pop("model", MODEL), api_base=srv.base, record_path=tmp_path / "rec.jsonl",
                           retry_wait=0.01, timeout=10, **kw)
    return VLMProposer(client, spec=f"litellm:{client.model}")


def user_text(body) -> str:
    return "\n".join(p["text"] for m in body["messages"] if isinstance(m["content"], list)
                     for p in m["content"] if p["type"] == "text")


def no_key_anywhere(root: Path):
    for f in root.rglob("*"):
        if f.is_file():
            assert KEY.encode() not in f.read_bytes(), f"API key leaked into {f}"


# ----------------------------------------------------------------------------------------------
def test_request_carries_image_prompt_and_key_header(srv, tmp_path, query):
    p = proposer(srv, tmp_path)
    out = p.propose_split(query, 3)
    assert len(srv.requests) == 1
    req = srv.requests[0]
    assert req["path"] == "/v1/chat/completions"
    assert req["headers"]["authorization"] == f"Bearer {KEY}"  # the key came from the environment
    body = req["body"]
    assert body["model"] == "test-model" and body["n"] == 3
    assert body["response_format"] == {"type": "json_object"}
    system, user = body["messages"]
    assert system["role"] == "system" and "Specification language" in system["content"]
    assert "reach(R)" in system["content"] and '"type": "disc"' in system["content"]
    images = [c for c in user["content"] if c["type"] == "image_url"]
    assert [i["image_url"]["url"] for i in images] == ["data:image/png;base64," + base64.b64encode(tiny_png()).decode()]
    text = user_text(body)
    for part in ("Maze 'split_doorway': 10 rows x 13 columns, cell size 1.0 m", "#SS...#####.#",  # environment
                 "Agent: point", "within 0.104 m", "origin at the map centre",  # clearance = 0.1 m + contact margin
                 "succeeded 10 times", "31.2%", "run 32 times",  # evaluation
                 '{"type": "box", "min": [1.5, -2.0], "max": [3.5, -1.0]}',  # goal region
                 "the maze walls", '"waypoints"', "at most 32"):  # avoid set, schema
        assert part in text, part
    assert out == [[Disc(-1.0, -2.5, 0.4), Disc(1.0, -2.5, 0.4)]] * 3
    assert p.calls == 1 and p.client.prompt_tokens == 1000 and p.client.completion_tokens == 100
    assert p.cost_usd == 0.0  # unknown local model: free, no crash
    assert p.history[0]["accepted"][0]["reasoning"] == "go through the lower doorway"
    no_key_anywhere(tmp_path)


def test_followup_carries_candidates_success_and_rollouts(srv, tmp_path, query):
    p = proposer(srv, tmp_path)
    fb = [CandidateFeedback([Disc(-1.0, -2.5, 0.4)], [0.9, 0.25], tiny_png((0, 255, 0))),
          CandidateFeedback([Disc(0.0, 2.5, 0.3), Disc(3.0, 3.5, 0.3)], [1.0, 0.5, 0.0], tiny_png((0, 0, 255)))]
    assert len(p.propose_split(query, 2, fb)) == 2
    body = srv.requests[0]["body"]
    text = user_text(body)
    assert "Candidate 1" in text and "Candidate 2" in text
    assert "START -> x1: 90.0%" in text and "x1 -> GOAL: 25.0%" in text and "x2 -> GOAL: 0.0%" in text
    assert "(product): 22.5%" in text and "best candidate so far reaches 22.5%" in text
    assert '[{"type": "disc", "center": [0.0, 2.5], "radius": 0.3}' in text
    urls = [c["image_url"]["url"] for c in body["messages"][1]["content"] if c["type"] == "image_url"]
    assert len(urls) == 3 and len(set(urls)) == 3  # the map + one rollout picture per candidate


@pytest.mark.parametrize("bad,why", [(MALFORMED, "not valid JSON"), (SCHEMA_BAD, "does not follow the schema"),
                                     (IN_WALL, "inside a wall")])
def test_each_bad_reply_is_rejected_and_reasked_once(srv, tmp_path, query, caplog, bad, why):
    srv.script[:] = [[GOOD, bad, GOOD2], [GOOD3]]
    p = proposer(srv, tmp_path)
    with caplog.at_level(logging.WARNING):
        out = p.propose_split(query, 3)
    assert [len(c) for c in out] == [2, 1, 1]
    assert len(srv.requests) == 2 and srv.requests[1]["body"].get("n", 1) == 1
    reask = srv.requests[1]["body"]["messages"]
    assert reask[-2] == {"role": "assistant", "content": bad}
    assert "1 of 3 of your answers could not be used" in reask[-1]["content"] and why in reask[-1]["content"]
    assert any(why in r.getMessage() and "rejected" in r.getMessage() for r in caplog.records)
    assert p.history[-1]["rejected"] and why in p.history[-1]["rejected"][0] and p.history[-1]["reasked"]


def test_all_bad_twice_gives_no_candidates_and_no_crash(srv, tmp_path, query, maze):
    srv.script[:] = [[MALFORMED, IN_WALL], [SCHEMA_BAD, "   "]]
    p = proposer(srv, tmp_path)
    assert p.propose_split(query, 2) == []
    assert len(srv.requests) == 2 and len(p.history[-1]["rejected"]) == 4  # asked once again, no more
    # a whole-graph reply that is no graph is rejected the same way
    srv.script[:] = [[GOOD], [GOOD]]
    gq = GraphQuery(maze, "point", maze_task(maze), 0.3, 32, tiny_png())
    assert p.propose_graph(gq, 1) == []


def test_retries_429_and_500_then_succeeds(srv, tmp_path, query, caplog):
    srv.script[:] = [429, 500, [GOOD]]
    p = proposer(srv, tmp_path, num_retries=3)
    with caplog.at_level(logging.WARNING):
        assert len(p.propose_split(query, 2)) == 2
    assert len(srv.requests) == 3
    msgs = [r.getMessage() for r in caplog.records]
    assert any("RateLimitError" in m and "retry 1/3" in m for m in msgs)
    assert any("InternalServerError" in m and "retry 2/3" in m for m in msgs)
    assert p.calls == 1 and p.client.attempts == 3
    assert KEY not in caplog.text
    lines = [json.loads(s) for s in (tmp_path / "rec.jsonl").read_text().splitlines()]
    assert [bool(rec["error"]) for rec in lines] == [True, True, False]


def test_failures_become_one_line_errors(srv, tmp_path, query, monkeypatch):
    srv.script[:] = [500, 500, 500]
    with pytest.raises(VLMUnavailable) as e:
        proposer(srv, tmp_path, num_retries=2).propose_split(query, 1)
    assert "test-model" in str(e.value) and "\n" not in str(e.value) and len(srv.requests) == 3
    srv.script[:] = [429, 429]
    with pytest.raises(VLMUnavailable, match="rate-limited"):
        proposer(srv, tmp_path, num_retries=1).propose_split(query, 1)
    srv.script[:] = [401]
    with pytest.raises(VLMConfigError, match="rejected the API key.*OPENAI_API_KEY"):
        proposer(srv, tmp_path).propose_split(query, 1)
    srv.script[:] = [404]
    with pytest.raises(VLMConfigError, match="unknown model litellm:openai/test-model"):
        proposer(srv, tmp_path).propose_split(query, 1)
    down = LiteLLMClient(MODEL, api_base="http://127.0.0.1:9/v1", record_path=tmp_path / "rec.jsonl",
                         num_retries=1, retry_wait=0.01, timeout=5)
    with pytest.raises(VLMUnavailable, match="unreachable") as e:
        VLMProposer(down).propose_split(query, 1)
    assert "\n" not in str(e.value)
    # configuration problems are caught before any call
    monkeypatch.delenv("OPENAI_API_KEY")
    with pytest.raises(VLMConfigError, match=r"^no API key for litellm:gpt-4o: set OPENAI_API_KEY"):
        make_proposer("litellm:gpt-4o", record_path=tmp_path / "x.jsonl")
    with pytest.raises(VLMConfigError, match="unknown model litellm:no-such-model-xyz"):
        make_proposer("litellm:no-such-model-xyz", record_path=tmp_path / "x.jsonl")
    with pytest.raises(SpecrefineError, match="invalid proposer"):
        make_proposer("vlm")
    assert isinstance(VLMConfigError("x"), SpecrefineError)
    no_key_anywhere(tmp_path)


def test_unsupported_params_fall_back(srv, tmp_path, query):
    p = proposer(srv, tmp_path)
    p.client._n_ok = False  # a provider without `n`: w separate calls
    assert len(p.propose_split(query, 3)) == 3
    assert len(srv.requests) == 3 and all("n" not in r["body"] for r in srv.requests)
    srv.requests.clear()
    srv.script[:] = [400, [GOOD]]  # e.g. the provider rejects response_format: dropped, asked again
    p = proposer(srv, tmp_path)
    assert len(p.propose_split(query, 1)) == 1
    assert "response_format" in srv.requests[0]["body"] and "response_format" not in srv.requests[1]["body"]


def test_cost_of_a_priced_model(srv, tmp_path, query):
    p = proposer(srv, tmp_path, model="openai/gpt-4o")
    p.propose_split(query, 1)
    assert p.cost_usd > 0  # 1000 prompt + 100 completion tokens at gpt-4o prices
    rec = json.loads((tmp_path / "rec.jsonl").read_text().splitlines()[-1])
    assert rec["cost_usd"] == pytest.approx(p.cost_usd) and rec["model"] == "openai/gpt-4o"


def run_session(p, query, maze):
    """A small run: split round 1, split round 2 with feedback (one bad reply, re-asked), one graph query."""
    out = [p.propose_split(query, 3)]
    fb = [CandidateFeedback(c, [0.5] * (len(c) + 1), tiny_png((i * 40, 0, 0))) for i, c in enumerate(out[0])]
    out.append(p.propose_split(query, 3, fb))
    gq = GraphQuery(maze, "point", maze_task(maze), 0.1, 32, tiny_png(), edge_success={("S", "G"): 0.1})
    out.append([g.to_dict() for g in p.propose_graph(gq, 2)])
    out.append([g.to_dict() for g in p.propose_graph(gq, 1, [GraphFeedback(maze_task(maze), {("S", "G"): 0.1})])])
    return out


def graph_reply(maze):
    return json.dumps({"reasoning": "lower doorway", "initial": "S", "finals": ["G"],
                       "vertices": [{"name": "S", "refines": "S", "region": None},
                                    {"name": "d", "refines": None,
                                     "region": {"type": "disc", "center": [0.0, -2.5], "radius": 0.4}},
                                    {"name": "G", "refines": "G", "region": None}],
                       "edges": [{"u": "S", "v": "d"}, {"from": "d", "to": "G"}]})


def test_replay_reproduces_a_recorded_run_exactly(srv, tmp_path, query, maze, caplog):
    rec = tmp_path / "vlm" / "run.jsonl"
    srv.script[:] = [[GOOD, GOOD2, GOOD3], [GOOD2, IN_WALL, GOOD], [GOOD3], [graph_reply(maze)], [graph_reply(maze)]]
    live = make_proposer(f"litellm:{MODEL}", record_path=rec, api_base=srv.base, retry_wait=0.01)
    recorded = run_session(live, query, maze)
    assert live.calls == len(srv.requests) == 5 and live.is_vlm
    graphs = recorded[2]
    assert len(graphs) == 2 and {v["name"] for v in graphs[0]["vertices"]} == {"S", "d", "G"}

    srv.requests.clear()
    replay = make_proposer(f"replay:{rec}")
    assert replay.is_vlm and "recorded openai/test-model" in replay.name
    assert run_session(replay, query, maze) == recorded
    assert srv.requests == [] and replay.calls == live.calls and replay.cost_usd == live.cost_usd
    assert replay.history == live.history

    # a request the recording never saw: one clear line
    other = EdgeQuery(maze, "point", maze.start, maze.goal, maze.walls, 0.9, 32, tiny_png())
    with pytest.raises(ReplayMiss, match=r"^replay:.*no recorded answer for this request") as e:
        make_proposer(f"replay:{rec}").propose_split(other, 1)
    assert "\n" not in str(e.value)
    # same text, different picture: answered from the text match with a warning (strict mode refuses)
    redrawn = EdgeQuery(maze, "point", maze.start, maze.goal, maze.walls, 0.3125, 32, tiny_png((9, 9, 9)))
    with caplog.at_level(logging.WARNING):
        assert make_proposer(f"replay:{rec}").propose_split(redrawn, 3) == recorded[0]
    assert any("pictures differ" in r.getMessage() for r in caplog.records)
    with pytest.raises(ReplayMiss):
        VLMProposer(ReplayClient(rec, strict=True)).propose_split(redrawn, 3)
    with pytest.raises(VLMConfigError, match="cannot read"):
        make_proposer(f"replay:{tmp_path / 'missing.jsonl'}")

    # the recording: one line per real call, images stored once by hash, no key anywhere
    lines = [json.loads(s) for s in rec.read_text().splitlines()]
    assert len(lines) == 5
    first = lines[0]
    assert first["model"] == MODEL and first["request"]["params"]["n"] == 3 and first["latency_s"] >= 0
    assert first["key"] == request_hash(split_messages(query))
    assert first["response"]["choices"][0]["text"] == GOOD
    img = [p for p in first["request"]["messages"][1]["content"] if p["type"] == "image_url"][0]["image_url"]["url"]
    assert re.fullmatch(r"sha256:[0-9a-f]{64}", img)
    assert (rec.parent / "run.images" / f"{img[7:]}.png").read_bytes() == tiny_png()
    flat = rec.read_text().lower()
    assert "authorization" not in flat and "api_key" not in flat
    no_key_anywhere(tmp_path)


def test_graph_reply_becomes_task_graph(maze):
    original = maze_task(maze)
    g, why = parse_graph(graph_reply(maze), maze, original)
    assert why == "lower doorway" and g.initial == "S" and g.finals == {"G"}
    assert g.g.nodes["S"]["refines"] == "S" and g.g.nodes["d"]["refines"] is None
    assert g.region("S") == original.region("S") and g.region("d") == Disc(0.0, -2.5, 0.4)
    assert g.g.edges["S", "d"]["parent"] == ("S", "G") and g.avoid("d", "G") == maze.walls
    assert check_refines(g, original) == []  # this reply happens to be a true refinement
    bad = json.loads(graph_reply(maze))
    bad["edges"].append({"u": "G", "v": "S"})
    with pytest.raises(ProposalRejected, match="cycle"):
        parse_graph(json.dumps(bad), maze, original)
    bad = json.loads(graph_reply(maze))
    bad["finals"] = ["d"]
    with pytest.raises(ProposalRejected, match="final vertex"):
        parse_graph(json.dumps(bad), maze, original)
    bad = json.loads(graph_reply(maze))
    bad["vertices"][1]["region"]["center"] = [0.0, 0.0]
    with pytest.raises(ProposalRejected, match="inside a wall"):
        parse_graph(json.dumps(bad), maze, original)


def test_one_shot_example_in_prompt_is_a_valid_answer():
    text = (Path(__file__).resolve().parent.parent / "prompts" / "graph_example.md").read_text()
    grid = [line.strip() for line in text.splitlines() if line.startswith("    #")]
    example = parse_maze("\n".join(grid), "example")
    answer = re.search(r"```json\n(.*?)```", text, re.DOTALL).group(1)
    g, why = parse_graph(answer, example, maze_task(example))
    assert len(g.vertices()) == 6 and len(g.edges()) == 5 and "corridor" in why
    assert check_refines(g, maze_task(example)) == []


def test_a_request_ends_at_its_deadline_with_one_line(srv, tmp_path, query, monkeypatch):
    srv.script[:] = [500] * 20
    client = LiteLLMClient(MODEL, api_base=srv.base, record_path=tmp_path / "rec.jsonl", retry_wait=1.0,
                           num_retries=10, timeout=10, deadline=0.5)
    t0 = time.monotonic()
    with pytest.raises(VLMUnavailable, match=r"no answer within the 0.5 s deadline .* after 1 attempts") as e:
        VLMProposer(client).propose_split(query, 1)
    assert time.monotonic() - t0 < 5 and "\n" not in str(e.value)  # not 10 retries with back-off
    monkeypatch.setenv("SPECREFINE_VLM_DEADLINE", "-1")
    with pytest.raises(VLMConfigError, match="SPECREFINE_VLM_DEADLINE"):
        LiteLLMClient(MODEL, api_base=srv.base, record_path=tmp_path / "rec.jsonl")


@pytest.mark.parametrize("retry_after,slept", [("2", 2.0), ("100000", 60.0)])
def test_retry_after_is_honoured_up_to_its_cap(srv, tmp_path, query, monkeypatch, retry_after, slept):
    from specrefine.vlm.client import MAX_RETRY_AFTER

    waits = []
    monkeypatch.setattr("specrefine.vlm.client.time.sleep", waits.append)
    srv.script[:] = [(429, {"Retry-After": retry_after}), [GOOD]]
    assert len(proposer(srv, tmp_path).propose_split(query, 1)) == 1
    assert waits == [slept] and MAX_RETRY_AFTER == 60.0  # not the 0.01 s back-off, and never 100000 s


ADDRESSES = [("ollama/llava", "OLLAMA_API_BASE"), ("ollama_chat/llava", "OLLAMA_API_BASE"),
             (MODEL, "OPENAI_BASE_URL"), (MODEL, "OPENAI_API_BASE")]


@pytest.mark.parametrize("model,variable", ADDRESSES)
def test_an_unreachable_provider_is_named_by_the_address_tried(srv, tmp_path, query, monkeypatch, model, variable):
    for name in ("OLLAMA_API_BASE", "OPENAI_BASE_URL", "OPENAI_API_BASE"):
        monkeypatch.delenv(name, raising=False)
    monkeypatch.setenv(variable, "http://user:secret@127.0.0.1:9/v1?token=x")
    client = LiteLLMClient(model, record_path=tmp_path / "rec.jsonl", num_retries=0, timeout=5)
    with pytest.raises(VLMUnavailable, match=r"unreachable or failing at http://127\.0\.0\.1:9/v1[ )]") as e:
        VLMProposer(client).propose_split(query, 1)
    assert "secret" not in str(e.value) and "token" not in str(e.value)
    if model.startswith("ollama"):
        assert "ollama serve" in str(e.value)
        monkeypatch.delenv(variable)
        assert LiteLLMClient(model, record_path=tmp_path / "rec.jsonl").endpoint == "http://localhost:11434"
    else:  # the address named is the one LiteLLM calls: pointed at the fake server, it answers
        monkeypatch.setenv(variable, srv.base)
        client = LiteLLMClient(model, record_path=tmp_path / "rec.jsonl", timeout=10)
        assert len(VLMProposer(client).propose_split(query, 1)) == 1 and len(srv.requests) == 1


NOT_JSON = b"<html><body>502 Bad Gateway, sent by a proxy as 200</body></html>"
NO_CHOICES = json.dumps({"id": "c", "object": "chat.completion", "created": 0, "model": "test-model", "choices": [],
                         "usage": {"prompt_tokens": 1, "completion_tokens": 0, "total_tokens": 1}}).encode()


@pytest.mark.parametrize("body,why", [(NOT_JSON, "no chat completion"), (b"{}", "no chat completion"),
                                      (b"null", "no chat completion"), (NO_CHOICES, "empty choices list")])
def test_a_reply_that_cannot_be_read_is_a_bad_answer_asked_again(srv, tmp_path, query, caplog, body, why):
    srv.script[:] = [body, [GOOD], body, [GOOD2]]
    p = proposer(srv, tmp_path)
    with caplog.at_level(logging.WARNING):
        first, second = p.propose_split(query, 2), p.propose_split(query, 2)
    assert first == [[Disc(-1.0, -2.5, 0.4), Disc(1.0, -2.5, 0.4)]] * 2 and len(second) == 2  # the run goes on
    assert len(srv.requests) == 4 and srv.requests[1]["body"]["n"] == 2  # re-asked for both answers
    assert len([r for r in caplog.records if why in r.getMessage()]) == 1  # warned once
    assert p.bad_replies == 4 and p.client.stats()["bad_replies"] == 4 and p.calls == 4
    assert p.history[0]["reasked"] and len(p.history[0]["rejected"]) == 2 and why in p.history[0]["rejected"][0]
    replay = make_proposer(f"replay:{tmp_path / 'rec.jsonl'}")  # recorded as the same bad answers
    assert replay.propose_split(query, 2) == first and replay.history == p.history[:1] and replay.bad_replies == 2


def test_a_reply_longer_than_the_cap_is_a_bad_answer_recorded_capped(srv, tmp_path, query):
    from specrefine.vlm import MAX_REPLY_CHARS

    srv.script[:] = [[GOOD + " " * MAX_REPLY_CHARS], [GOOD]]  # valid JSON, a megabyte of it
    p = proposer(srv, tmp_path)
    out = p.propose_split(query, 1)
    assert out == [[Disc(-1.0, -2.5, 0.4), Disc(1.0, -2.5, 0.4)]]  # from the re-ask
    assert p.bad_replies == 1 and "longer than the cap of 1,000,000 characters" in p.history[0]["rejected"][0]
    record = tmp_path / "rec.jsonl"
    (choice,) = json.loads(record.read_text().splitlines()[0])["response"]["choices"]
    assert len(choice["text"]) == MAX_REPLY_CHARS and "MAX_REPLY_CHARS" in choice["bad"]
    assert record.stat().st_size < MAX_REPLY_CHARS + 100_000
    replay = make_proposer(f"replay:{record}")
    assert replay.propose_split(query, 1) == out and replay.bad_replies == 1


# --- snapping a waypoint centred in a wall (EdgeQuery.snap; method ours-corrector-snap) -----------------------------
def test_a_waypoint_centred_in_a_wall_is_moved_clear_of_it_when_asked_to_snap(maze, caplog):
    from specrefine.proposers.schema import parse_split

    with pytest.raises(ProposalRejected, match="inside a wall"):
        parse_split(IN_WALL, maze)
    with caplog.at_level(logging.WARNING):
        (moved,), _ = parse_split(IN_WALL, maze, snap=0.11)
    assert "waypoint 1 centre (0, 0) lies inside a wall" in caplog.text and "moved to (" in caplog.text
    assert isinstance(moved, Disc) and moved.r == pytest.approx(0.4)
    centre = np.asarray(moved.centre())
    assert float(maze.obstacles.signed_distance(centre[None])[0]) >= 0.11
    assert 0 < np.hypot(*centre) <= maze.cell_size * np.sqrt(2)  # the nearest clear point, within one cell
    assert parse_split(GOOD, maze, snap=0.11) == parse_split(GOOD, maze)  # a valid reply is untouched


def test_a_waypoint_with_no_clear_point_within_a_cell_is_still_rejected():
    from specrefine.proposers.schema import parse_split

    solid = parse_maze("#######\n#S...G#\n#######\n#######\n#######\n#######\n#######", "solid")
    x, y = solid.cell_to_xy(5, 3)  # three cells below the corridor: every point within one cell is in a wall
    reply = json.dumps({"waypoints": [{"type": "disc", "center": [float(x), float(y)], "radius": 0.3}]})
    with pytest.raises(ProposalRejected, match="inside a wall"):
        parse_split(reply, solid, snap=0.11)


def test_the_proposer_snaps_only_when_the_query_asks(srv, tmp_path, query):
    from dataclasses import replace

    srv.script[:] = [[IN_WALL], [IN_WALL]]
    assert proposer(srv, tmp_path).propose_split(query, 1) == []
    srv.script[:] = [[IN_WALL]]
    (waypoints,) = proposer(srv, tmp_path).propose_split(replace(query, snap=0.11), 1)
    assert len(waypoints) == 1 and float(query.maze.obstacles.signed_distance(
        np.asarray(waypoints[0].centre())[None])[0]) >= 0.11
