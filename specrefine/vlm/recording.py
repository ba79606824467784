"""Record and replay: every real VLM call appended to a JSONL file, and a client that answers from one.

A recording (see ``data/vlm/README.md``) holds one JSON line per call; PNG images go once each to
``<stem>.images/<sha256>.png``.  :class:`ReplayClient` answers deterministically, matching requests
by :func:`~specrefine.vlm.messages.request_hash` (text and images).
"""

from __future__ import annotations

import base64
import json
import logging
import re
from pathlib import Path

from ..core.errors import ReplayMiss, SpecrefineError, VLMConfigError
from ..core.paths import data_dir, regular_file
from ..core.runfolder import open_append, write_atomic, write_error
from .messages import (
    MAX_REPLY_CHARS,
    TOO_LONG,
    VLMClient,
    _image_digest,
    _map_parts,
    _secret_values,
    request_hash,
    scrub,
    scrub_text,
)

log = logging.getLogger(__name__)

RECORD_VERSION = 1


def record_dir() -> Path:
    """Where recordings go by default: ``data/vlm/`` (of the checkout, or of the installed package)."""
    return data_dir() / "vlm"


def slug(text: str) -> str:
    return re.sub(r"[^A-Za-z0-9._-]+", "_", text).strip("_") or "model"


def default_record_path(model: str) -> Path:
    return record_dir() / f"{slug(model)}.jsonl"


class Recorder:
    """Appends one JSON line per real call; PNG images go once each to ``<stem>.images/<sha256>.png``."""

    def __init__(self, path: str | Path):
        self.path = Path(path)
        self.image_dir = self.path.with_suffix("").with_name(self.path.stem + ".images")

    def _store_messages(self, messages: list[dict]) -> list[dict]:
        """Messages as recorded: each image stored once as a PNG file and referred to by its digest."""
        return _map_parts(messages, lambda url: {"type": "image_url", "image_url": {"url": self._store_image(url)}},
                          dict)

    def _store_image(self, url: str) -> str:
        digest = _image_digest(url)
        if not digest:
            return url
        self.image_dir.mkdir(parents=True, exist_ok=True)
        target = self.image_dir / f"{digest.split(':', 1)[1]}.png"
        if not target.is_file() or target.is_symlink():  # a link is replaced, never written through
            write_atomic(target, base64.b64decode(url.split(";base64,", 1)[1]))
        return digest

    def write(self, record: dict, messages: list[dict]) -> None:
        record = dict(record)
        record["request"] = dict(record.get("request", {}), messages=self._store_messages(messages))
        secrets = _secret_values()
        line = json.dumps(scrub(record, secrets), ensure_ascii=False, sort_keys=False)
        # belt and braces: no long secret survives, whatever field it hid in (short ones could match JSON syntax)
        line = scrub_text(line, secrets, long_only=True)
        self.path.parent.mkdir(parents=True, exist_ok=True)
        with open_append(self.path, "recording") as fh:  # a link or a FIFO is refused, never written through
            try:
                fh.write(line + "\n")
                fh.flush()
            except OSError as exc:  # a full disk: one line, not a traceback
                raise write_error(self.path, exc) from None


def _parse_record(line: bytes) -> dict | None:
    """One recording line as a record dict, or None when it is not UTF-8 JSON of a recorded call's shape."""
    try:
        rec = json.loads(line.decode("utf-8"))
    except (UnicodeDecodeError, ValueError):
        return None
    if not isinstance(rec, dict):
        return None
    if rec.get("error") or not rec.get("response"):
        return {**rec, "response": None}  # a failed call: nothing to replay
    return rec if _answer_shape(rec) else None


def _number(value) -> bool:
    return value is None or (isinstance(value, (int, float)) and not isinstance(value, bool))


def _answer_shape(rec: dict) -> bool:
    response = rec["response"]
    if not isinstance(response, dict) or not isinstance(response.get("usage", {}), dict):
        return False
    choices, usage = response.get("choices", []), response.get("usage", {})
    return (isinstance(choices, list) and all(isinstance(c, dict) and isinstance(c.get("text", ""), str)
                                              and isinstance(c.get("bad") or "", str) for c in choices)
            and all(isinstance(rec.get(k), (str, type(None))) for k in ("key", "text_key"))
            and all(_number(v) for v in (usage.get("prompt_tokens"), usage.get("completion_tokens"),
                                         rec.get("cost_usd"))))


class ReplayClient(VLMClient):
    """Answers from a JSONL recording; request ``i`` with hash ``h`` gets the ``i``-th recorded answers for ``h``.

    When no recorded request has the same hash, a request whose text (ignoring images) matches is
    used instead with a logged warning, unless ``strict``; with no match at all it raises
    :class:`ReplayMiss`.
    """

    def __init__(self, path: str | Path, *, strict: bool = False):
        super().__init__()
        self.path = Path(path)
        self.strict = strict
        try:
            lines = regular_file(self.path, "the recording").read_bytes().splitlines()
        except SpecrefineError as exc:
            raise VLMConfigError(f"replay:{exc}") from None
        except OSError as exc:
            raise VLMConfigError(f"replay:{path}: cannot read the recording ({exc.strerror or exc})") from None
        self.records: list[dict] = []
        bad = []  # line numbers that are not UTF-8 JSON of a recorded call's shape
        for lineno, line in enumerate(lines, start=1):
            if not line.strip():
                continue
            rec = _parse_record(line)
            if rec is None:
                bad.append(lineno)
            elif not rec.get("error") and rec["response"]:
                self.records.append(rec)
        if not self.records:
            unreadable = f" ({len(bad)} unreadable lines, the first line {bad[0]})" if bad else ""
            raise VLMConfigError(f"replay:{path}: the recording holds no answered calls{unreadable}")
        if bad:
            log.warning("replay %s: %d unreadable lines skipped (not UTF-8 JSON of a recorded call; the first: "
                        "line %d)", path, len(bad), bad[0])
        models = sorted({r.get("model", "?") for r in self.records})
        self.model = models[0] if len(models) == 1 else "+".join(models)
        self.name = f"replay:{path}"
        self._entries: list[tuple[int, str, str | None]] = []  # (record index, text, why it cannot be used)
        self._by_key: dict[str, list[int]] = {}
        self._by_text: dict[str, list[int]] = {}
        for i, rec in enumerate(self.records):
            for choice in rec["response"].get("choices", []):
                e = len(self._entries)
                text = choice.get("text", "")
                why = choice.get("bad") or (TOO_LONG if len(text) > MAX_REPLY_CHARS else None)
                self._entries.append((i, text, why))
                self._by_key.setdefault(rec.get("key"), []).append(e)
                self._by_text.setdefault(rec.get("text_key"), []).append(e)
        self._used: set[int] = set()
        self._charged: set[int] = set()
        self._warned_text_match = False

    def complete(self, messages: list[dict], n: int = 1) -> list[str]:
        key = request_hash(messages)
        picked = [e for e in self._by_key.get(key, []) if e not in self._used][:n]
        if len(picked) < n and not self.strict:
            extra = [e for e in self._by_text.get(request_hash(messages, images=False), [])
                     if e not in self._used and e not in picked][: n - len(picked)]
            if extra and not self._warned_text_match:
                log.warning("replay %s: answering from a recording whose text matches but whose pictures differ "
                            "(rendering or rollouts changed since recording)", self.path)
                self._warned_text_match = True
            picked += extra
        if not picked:
            raise ReplayMiss(f"replay:{self.path}: no recorded answer for this request (hash {key[:12]}); "
                             f"the run differs from the recorded one: record it again with --proposer litellm:MODEL")
        if len(picked) < n:
            log.warning("replay %s: only %d of %d answers recorded for request %s", self.path, len(picked), n,
                        key[:12])
        self._used.update(picked)
        self.attempts += 1
        for rec_i in sorted({self._entries[e][0] for e in picked} - self._charged):
            self._charged.add(rec_i)
            rec = self.records[rec_i]
            usage = rec["response"].get("usage", {})
            self.calls += 1
            self.prompt_tokens += int(usage.get("prompt_tokens", 0) or 0)
            self.completion_tokens += int(usage.get("completion_tokens", 0) or 0)
            self.cost_usd += float(rec.get("cost_usd", 0.0) or 0.0)  # what the recorded run spent
        return [self.bad(why) if why else text for _, text, why in (self._entries[e] for e in picked)]
