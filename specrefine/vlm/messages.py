"""Chat messages as the VLM clients see them: text and PNG parts, a stable request hash, a readable
transcript, the scrubbing of secrets, and :class:`VLMClient`, what a proposer needs from a model.

A reply a client cannot read (an HTTP 200 that is no chat completion, an empty ``choices`` list, a text
longer than :data:`MAX_REPLY_CHARS`) comes back as a :class:`BadReply`: counted, warned about once, and
dropped by the proposer like any bad answer, which then asks again.

Keys are read by LiteLLM from the environment only; :func:`scrub` keeps every key-like value out
of anything this package writes (recordings, logs, error messages): the value of every set environment
variable whose name looks like a key, whatever its length.  A value of 8 characters or more is replaced
wherever it occurs; a shorter one (a test key, a 1-2 character placeholder) only where it stands as a whole
token, so that a key ``ab`` hides ``ab`` but leaves ``table`` alone; flag values (``true``, ``0``, ...) of
variables such as ``TOKENIZERS_PARALLELISM`` are no secrets and are left alone.
"""

from __future__ import annotations

import base64
import hashlib
import json
import logging
import os
import re
from typing import Any

log = logging.getLogger(__name__)

_SECRET_ENV = re.compile(r"(API_?KEY|_KEY$|TOKEN|SECRET|PASSWORD|CREDENTIAL)", re.IGNORECASE)
_SECRET_FIELDS = {"api_key", "apikey", "authorization", "x-api-key", "x-goog-api-key", "api-key", "access_token",
                  "proxy-authorization", "aws_secret_access_key", "aws_session_token"}


#: The longest reply text a proposer reads and a recording keeps (characters).  A longer reply is a bad
#: answer (dropped and asked again, like malformed JSON); its recording holds its first MAX_REPLY_CHARS.
MAX_REPLY_CHARS = 1_000_000

LONG_SECRET = 8  # a secret this long is replaced anywhere; a shorter one only as a whole token
_FLAGS = {"", "0", "1", "true", "false", "yes", "no", "on", "off", "none", "null"}


def _secret_values() -> list[str]:
    vals = {v for k, v in os.environ.items()
            if _SECRET_ENV.search(k) and isinstance(v, str) and v.strip().lower() not in _FLAGS}
    return sorted(vals, key=len, reverse=True)


def scrub_text(text: str, secrets: list[str], long_only: bool = False) -> str:
    """``text`` with each secret replaced by ``***`` (short ones only as whole tokens; none if ``long_only``)."""
    for s in secrets:
        if len(s) >= LONG_SECRET:
            text = text.replace(s, "***")
        elif not long_only and s in text:
            text = re.sub(rf"(?<![\w-]){re.escape(s)}(?![\w-])", "***", text)
    return text


def scrub(obj: Any, secrets: list[str] | None = None) -> Any:
    """Copy of ``obj`` with key-like fields dropped and every secret env value replaced by ``***``."""
    secrets = _secret_values() if secrets is None else secrets
    if isinstance(obj, dict):
        return {k: scrub(v, secrets) for k, v in obj.items() if str(k).lower() not in _SECRET_FIELDS}
    if isinstance(obj, (list, tuple)):
        return [scrub(v, secrets) for v in obj]
    if isinstance(obj, str):
        return scrub_text(obj, secrets)
    return obj


def one_line(exc: BaseException | str, limit: int = 240) -> str:
    text = str(exc).strip().replace("\r", " ")
    text = " ".join(part.strip() for part in text.splitlines() if part.strip()) or type(exc).__name__
    text = scrub(text)
    return text if len(text) <= limit else text[: limit - 3] + "..."


def text_part(text: str) -> dict:
    return {"type": "text", "text": text}


def image_part(png: bytes) -> dict:
    return {"type": "image_url", "image_url": {"url": "data:image/png;base64," + base64.b64encode(png).decode()}}


_IMAGE_MARK = re.compile(r"\[\[image:(\w+)\]\]")


def build_content(text: str, images: dict[str, bytes | None]) -> list[dict]:
    """Split ``text`` at ``[[image:NAME]]`` markers into text parts and PNG image parts."""
    parts: list[dict] = []
    pos = 0
    for m in _IMAGE_MARK.finditer(text):
        chunk = text[pos:m.start()].strip()
        if chunk:
            parts.append(text_part(chunk))
        png = images.get(m.group(1))
        parts.append(image_part(png) if png else text_part("(no picture available for this item)"))
        pos = m.end()
    tail = text[pos:].strip()
    if tail:
        parts.append(text_part(tail))
    return parts


def _image_digest(url: str) -> str | None:
    if url.startswith("data:") and ";base64," in url:
        return "sha256:" + hashlib.sha256(base64.b64decode(url.split(";base64,", 1)[1])).hexdigest()
    return None


def _map_parts(messages: list[dict], image_part, other_part) -> list[dict]:
    """A copy of ``messages`` with each image part replaced by ``image_part(url)``, any other by ``other_part(p)``."""
    out = []
    for msg in messages:
        content = msg.get("content")
        if isinstance(content, list):
            content = [image_part(_image_url(p)) if p.get("type") == "image_url" else other_part(p) for p in content]
        out.append({"role": msg.get("role"), "content": content})
    return out


def _image_url(part: dict) -> str:
    url = part.get("image_url")
    return url["url"] if isinstance(url, dict) else url


def _canonical(messages: list[dict], images: bool) -> list[dict]:
    return _map_parts(
        messages,
        lambda url: {"type": "image_url", "image": (_image_digest(url) or url) if images else "image"},
        lambda p: {"type": p.get("type"), "text": p.get("text")})


def request_hash(messages: list[dict], images: bool = True) -> str:
    """Stable SHA-256 of the request messages; images enter by the hash of their PNG bytes."""
    blob = json.dumps(_canonical(messages, images), sort_keys=True, separators=(",", ":"), ensure_ascii=True)
    return hashlib.sha256(blob.encode()).hexdigest()


def messages_to_text(messages: list[dict]) -> str:
    """Readable transcript of a request (images shown as ``[image]``): for notebooks and logs."""
    lines = []
    for msg in messages:
        lines.append(f"=== {msg.get('role')} ===")
        content = msg.get("content")
        if isinstance(content, str):
            lines.append(content)
            continue
        for p in content or []:
            lines.append("[image]" if p.get("type") == "image_url" else p.get("text", ""))
    return "\n".join(lines)


class BadReply(str):
    """An answer a client could not read (no chat completion, no choices, too long): empty text with the reason.

    A proposer drops it like any bad answer and asks again; the client has logged a warning for it.
    """

    def __new__(cls, reason: str):
        reply = super().__new__(cls, "")
        reply.reason = reason
        return reply


TOO_LONG = f"a reply longer than the cap of {MAX_REPLY_CHARS:,} characters (MAX_REPLY_CHARS)"


class VLMClient:
    """What a proposer needs from a model: ``complete(messages, n) -> n reply texts``."""

    model: str = "?"
    name: str = "?"

    def __init__(self):
        self.calls = 0  # completion calls that returned an answer
        self.attempts = 0  # including failed and retried ones
        self.prompt_tokens = 0
        self.completion_tokens = 0
        self.cost_usd = 0.0
        self.bad_replies = 0  # answers that could not be read (see BadReply)
        self._warned: set[str] = set()

    def complete(self, messages: list[dict], n: int = 1) -> list[str]:  # pragma: no cover - abstract
        raise NotImplementedError

    def bad(self, reason: str) -> BadReply:
        """An answer that cannot be read: counted, and warned about once per reason."""
        self.bad_replies += 1
        if reason not in self._warned:
            self._warned.add(reason)
            log.warning("%s: %s; dropped as a bad answer and asked again (counted from now on, not logged)",
                        self.name, reason)
        return BadReply(reason)

    def stats(self) -> dict:
        return {"model": self.model, "calls": self.calls, "attempts": self.attempts,
                "prompt_tokens": self.prompt_tokens, "completion_tokens": self.completion_tokens,
                "cost_usd": round(self.cost_usd, 6), "bad_replies": self.bad_replies}
