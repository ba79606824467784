"""One client for any vision-language model LiteLLM speaks, record/replay, and the proposal schema.

* :class:`LiteLLMClient` calls ``litellm.completion`` for any model string (``gpt-4o``,
  ``gemini/gemini-2.0-flash``, ``anthropic/claude-sonnet-4-5``, ``ollama/llava``, ...): images go as
  base64 PNG data URLs, ``w`` samples per query (``n`` where the provider has it, else ``w`` calls),
  JSON response format where supported, timeouts, and logged retries with back-off on rate limits,
  server errors and dropped connections.  Tokens and cost are counted per call (cost 0 for models
  LiteLLM has no price for).  Keys are read by LiteLLM from the environment only; nothing this
  module writes (recordings, logs, error messages) ever contains them.
* Every real call is appended to a JSONL recording (see ``data/vlm/README.md``);
  :class:`ReplayClient` answers from such a file deterministically, matched by a stable hash of
  the request messages (text and images).
* The proposal schema (pydantic) and its validation against a maze: :func:`parse_split` for an
  edge split (an ordered list of waypoint regions) and :func:`parse_graph` for a whole task graph
  (the one-shot baseline).  A bad reply raises :class:`ProposalRejected` with a one-line reason.
* Prompt templates live in ``prompts/`` (``$name`` placeholders, ``[[image:NAME]]`` markers);
  :func:`render_prompt` and :func:`build_content` turn them into chat messages.
"""

from __future__ import annotations

import os

os.environ.setdefault("LITELLM_LOCAL_MODEL_COST_MAP", "True")  # never fetch the price list at import

import base64  # noqa: E402
import hashlib  # noqa: E402
import json  # noqa: E402
import logging  # noqa: E402
import re  # noqa: E402
import time  # noqa: E402
from datetime import UTC, datetime  # noqa: E402
from pathlib import Path  # noqa: E402
from string import Template  # noqa: E402
from typing import Annotated, Any, Literal  # noqa: E402

import numpy as np  # noqa: E402
from pydantic import BaseModel, BeforeValidator, ConfigDict, Field, ValidationError, model_validator  # noqa: E402

from .errors import (  # noqa: E402
    ProposalRejected,
    ReplayMiss,
    SpecrefineError,
    VLMConfigError,
    VLMError,
    VLMUnavailable,
)
from .regions import Box, Disc, Region  # noqa: E402

log = logging.getLogger(__name__)

ROOT = Path(__file__).resolve().parent.parent
PROMPT_DIR = ROOT / "prompts"
RECORD_DIR = ROOT / "data" / "vlm"
RECORD_VERSION = 1


# --------------------------------------------------------------------------------------------
# secrets: never written anywhere
# --------------------------------------------------------------------------------------------
_SECRET_ENV = re.compile(r"(API_?KEY|_KEY$|TOKEN|SECRET|PASSWORD|CREDENTIAL)", re.IGNORECASE)
_SECRET_FIELDS = {"api_key", "apikey", "authorization", "x-api-key", "x-goog-api-key", "api-key", "access_token",
                  "proxy-authorization", "aws_secret_access_key", "aws_session_token"}


def _secret_values() -> list[str]:
    vals = {v for k, v in os.environ.items() if _SECRET_ENV.search(k) and isinstance(v, str) and len(v) >= 8}
    return sorted(vals, key=len, reverse=True)


def scrub(obj: Any, secrets: list[str] | None = None) -> Any:
    """Copy of ``obj`` with key-like fields dropped and every secret env value replaced by ``***``."""
    secrets = _secret_values() if secrets is None else secrets
    if isinstance(obj, dict):
        return {k: scrub(v, secrets) for k, v in obj.items() if str(k).lower() not in _SECRET_FIELDS}
    if isinstance(obj, (list, tuple)):
        return [scrub(v, secrets) for v in obj]
    if isinstance(obj, str):
        for s in secrets:
            if s in obj:
                obj = obj.replace(s, "***")
        return obj
    return obj


def one_line(exc: BaseException | str, limit: int = 240) -> str:
    text = str(exc).strip().replace("\r", " ")
    text = " ".join(part.strip() for part in text.splitlines() if part.strip()) or type(exc).__name__
    text = scrub(text)
    return text if len(text) <= limit else text[: limit - 3] + "..."


# --------------------------------------------------------------------------------------------
# messages, templates, hashing
# --------------------------------------------------------------------------------------------
def text_part(text: str) -> dict:
    return {"type": "text", "text": text}


def image_part(png: bytes) -> dict:
    return {"type": "image_url", "image_url": {"url": "data:image/png;base64," + base64.b64encode(png).decode()}}


_COMMENT = re.compile(r"\A\s*<!--.*?-->\s*", re.DOTALL)
_IMAGE_MARK = re.compile(r"\[\[image:(\w+)\]\]")


def load_prompt(name: str) -> str:
    """Template text of ``prompts/NAME.md`` without its leading ``<!-- ... -->`` comment."""
    path = PROMPT_DIR / f"{name}.md"
    try:
        return _COMMENT.sub("", path.read_text(), count=1)
    except OSError as exc:
        raise SpecrefineError(f"{path}: cannot read prompt template ({exc.strerror or exc})") from None


def render_prompt(name: str, **values) -> str:
    """Fill ``prompts/NAME.md`` (``$name`` placeholders; ``$$`` is a literal dollar)."""
    try:
        return Template(load_prompt(name)).substitute({k: str(v) for k, v in values.items()}).strip()
    except KeyError as exc:
        raise SpecrefineError(f"prompts/{name}.md: no value for placeholder ${exc.args[0]}") from None


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


# --------------------------------------------------------------------------------------------
# clients
# --------------------------------------------------------------------------------------------
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

    def complete(self, messages: list[dict], n: int = 1) -> list[str]:  # pragma: no cover - abstract
        raise NotImplementedError

    def stats(self) -> dict:
        return {"model": self.model, "calls": self.calls, "attempts": self.attempts,
                "prompt_tokens": self.prompt_tokens, "completion_tokens": self.completion_tokens,
                "cost_usd": round(self.cost_usd, 6)}


_LOCAL_PROVIDERS = {"ollama", "ollama_chat", "vllm", "hosted_vllm", "lm_studio", "llamafile", "openai_like"}
_KEY_VARS = {"openai": "OPENAI_API_KEY", "gemini": "GEMINI_API_KEY", "anthropic": "ANTHROPIC_API_KEY",
             "ollama": "OLLAMA_API_BASE", "ollama_chat": "OLLAMA_API_BASE", "mistral": "MISTRAL_API_KEY",
             "groq": "GROQ_API_KEY", "openrouter": "OPENROUTER_API_KEY", "azure": "AZURE_API_KEY",
             "together_ai": "TOGETHERAI_API_KEY", "deepseek": "DEEPSEEK_API_KEY", "xai": "XAI_API_KEY"}
_MODEL_HINT = "use a LiteLLM model string such as gpt-4o, gemini/gemini-2.0-flash, anthropic/claude-sonnet-4-5 " \
              "or ollama/llava"


def _litellm():
    import litellm

    litellm.suppress_debug_info = True
    return litellm


def _priced(lt, model: str) -> bool:
    try:
        info = lt.get_model_info(model)
    except Exception:  # noqa: BLE001 - unknown to LiteLLM
        return False
    return bool(info.get("input_cost_per_token") or info.get("output_cost_per_token"))


def _safe_url(url: str | None) -> str | None:
    """``url`` without any ``user:password@`` part or query string."""
    if not url:
        return url
    url = re.sub(r"//[^/@]*@", "//", url)
    return url.split("?", 1)[0]


def slug(text: str) -> str:
    return re.sub(r"[^A-Za-z0-9._-]+", "_", text).strip("_") or "model"


def default_record_path(model: str) -> Path:
    return RECORD_DIR / f"{slug(model)}.jsonl"


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
        if not target.exists():
            target.write_bytes(base64.b64decode(url.split(";base64,", 1)[1]))
        return digest

    def write(self, record: dict, messages: list[dict]) -> None:
        record = dict(record)
        record["request"] = dict(record.get("request", {}), messages=self._store_messages(messages))
        secrets = _secret_values()
        line = json.dumps(scrub(record, secrets), ensure_ascii=False, sort_keys=False)
        for s in secrets:  # belt and braces: no secret value survives, whatever field it hid in
            line = line.replace(s, "***")
        self.path.parent.mkdir(parents=True, exist_ok=True)
        with self.path.open("a", encoding="utf-8") as fh:
            fh.write(line + "\n")


class LiteLLMClient(VLMClient):
    """``litellm.completion`` for any model; see the module docstring."""

    def __init__(self, model: str, *, record_path: str | Path | None = None, record: bool = True,
                 api_base: str | None = None, timeout: float = 120.0, num_retries: int = 3,
                 retry_wait: float = 2.0, json_mode: bool = True, temperature: float | None = None,
                 max_tokens: int | None = None, check_env: bool = True):
        super().__init__()
        self.model = model
        self.name = f"litellm:{model}"
        self.api_base = api_base
        self.timeout = float(timeout)
        self.num_retries = int(num_retries)
        self.retry_wait = float(retry_wait)
        self.temperature, self.max_tokens = temperature, max_tokens
        self.recorder = Recorder(record_path or default_record_path(model)) if record else None
        lt = _litellm()
        try:
            _, self.provider, _, _ = lt.get_llm_provider(model, api_base=api_base)
        except Exception:
            raise VLMConfigError(f"unknown model litellm:{model}: LiteLLM cannot tell its provider; "
                                 f"{_MODEL_HINT}") from None
        self.key_var = _KEY_VARS.get(self.provider, f"{self.provider.upper()}_API_KEY")
        if check_env:
            self._check_env(lt)
        try:
            params = lt.get_supported_openai_params(model=model, custom_llm_provider=self.provider) or []
        except Exception:
            params = []
        self._n_ok = "n" in params
        self._json_ok = bool(json_mode) and "response_format" in params
        local = self.provider in _LOCAL_PROVIDERS or bool(api_base and re.search(r"//(localhost|127\.|\[::1\])",
                                                                                  api_base))
        if local and not _priced(lt, model):  # a local model LiteLLM has no price for: register it as free
            try:
                lt.register_model({model: {"input_cost_per_token": 0.0, "output_cost_per_token": 0.0,
                                           "litellm_provider": self.provider, "mode": "chat"}})
            except Exception:  # pragma: no cover - registration is a nicety
                pass
        self._unpriced_warned = False

    def _check_env(self, lt) -> None:
        try:
            env = lt.validate_environment(model=self.model, api_base=self.api_base)
        except TypeError:  # older signature
            env = lt.validate_environment(model=self.model)
        except Exception:
            return
        missing = [k for k in env.get("missing_keys", []) if not k.endswith("_API_BASE")]  # bases have defaults
        if missing and not env.get("keys_in_environment", False):
            if self.provider == "gemini":  # either name works
                what = "GEMINI_API_KEY (or GOOGLE_API_KEY)"
            else:
                what = " and ".join(sorted(missing, key=lambda k: k != self.key_var))
            raise VLMConfigError(f"no API key for litellm:{self.model}: set {what} in the environment "
                                 f"(keys are read from the environment only)")

    # -- one request -------------------------------------------------------------------------
    def complete(self, messages: list[dict], n: int = 1) -> list[str]:
        texts: list[str] = []
        for _ in range(n + 1):  # n calls at most when the provider has no `n`, plus one spare
            if len(texts) >= n:
                break
            want = n - len(texts) if self._n_ok else 1
            texts += self._call(messages, want)
        return texts[:n]

    def _kwargs(self, messages, n) -> dict:
        kw: dict[str, Any] = {"model": self.model, "messages": messages, "timeout": self.timeout,
                              "num_retries": 0, "max_retries": 0}  # retries are ours (logged), not nested
        if self.api_base:
            kw["api_base"] = self.api_base
        if n > 1:
            kw["n"] = n
        if self._json_ok:
            kw["response_format"] = {"type": "json_object"}
        if self.temperature is not None:
            kw["temperature"] = self.temperature
        if self.max_tokens is not None:
            kw["max_tokens"] = self.max_tokens
        return kw

    def _call(self, messages: list[dict], n: int) -> list[str]:
        lt = _litellm()
        retryable = tuple(c for c in (getattr(lt, name, None) for name in (
            "RateLimitError", "InternalServerError", "ServiceUnavailableError", "APIConnectionError", "Timeout",
            "BadGatewayError")) if isinstance(c, type))
        auth = tuple(c for c in (getattr(lt, "AuthenticationError", None), getattr(lt, "PermissionDeniedError", None))
                     if isinstance(c, type))
        not_found = getattr(lt, "NotFoundError", ())
        bad_request = getattr(lt, "BadRequestError", ())
        rate_limit = getattr(lt, "RateLimitError", ())
        key, text_key = request_hash(messages), request_hash(messages, images=False)
        attempt = 0
        while True:
            attempt += 1
            self.attempts += 1
            kw = self._kwargs(messages, n)
            t0 = time.time()
            try:
                resp = lt.completion(**kw)
            except Exception as exc:  # noqa: BLE001 - every provider failure becomes one line or a retry
                latency = time.time() - t0
                self._record(kw, messages, key, text_key, None, 0.0, latency, attempt, error=one_line(exc))
                if isinstance(exc, bad_request) and not isinstance(exc, (not_found, *auth)) and (
                        "n" in kw or "response_format" in kw):
                    dropped = "response_format" if "response_format" in kw else "n"  # one at a time
                    log.warning("VLM %s rejected the request (%s); retrying without %s", self.model,
                                one_line(exc, 120), dropped)
                    if dropped == "response_format":
                        self._json_ok = False
                    else:
                        self._n_ok, n = False, 1
                    continue
                if isinstance(exc, auth):
                    raise VLMConfigError(f"litellm:{self.model}: the provider rejected the API key "
                                         f"({type(exc).__name__}); check {self.key_var}") from None
                if isinstance(exc, not_found):
                    raise VLMConfigError(f"unknown model litellm:{self.model}: the provider does not know it "
                                         f"(404); {_MODEL_HINT}") from None
                if isinstance(exc, retryable) and attempt <= self.num_retries:
                    wait = self._wait(exc, attempt)
                    log.warning("VLM %s: %s (%s); retry %d/%d in %.1fs", self.model, type(exc).__name__,
                                one_line(exc, 100), attempt, self.num_retries, wait)
                    time.sleep(wait)
                    continue
                if isinstance(exc, rate_limit):
                    raise VLMUnavailable(f"litellm:{self.model}: rate-limited by the provider after {attempt} "
                                         f"attempts; wait and rerun, or lower -w / the number of edges") from None
                if isinstance(exc, retryable):
                    where = f" at {_safe_url(self.api_base)}" if self.api_base else ""
                    if self.provider.startswith("ollama") and not self.api_base:
                        where = " (is `ollama serve` running? set OLLAMA_API_BASE if it is not at localhost:11434)"
                    raise VLMUnavailable(f"litellm:{self.model}: provider unreachable or failing{where} after "
                                         f"{attempt} attempts ({one_line(exc, 120)})") from None
                raise VLMError(f"litellm:{self.model}: call failed: {one_line(exc, 160)}") from None
            latency = time.time() - t0
            texts, finish = [], []
            for choice in getattr(resp, "choices", None) or []:
                msg = getattr(choice, "message", None)
                content = getattr(msg, "content", None)
                if isinstance(content, list):  # some providers return content parts
                    content = "".join(p.get("text", "") if isinstance(p, dict) else str(p) for p in content)
                texts.append(content if isinstance(content, str) else "")
                finish.append(getattr(choice, "finish_reason", None))
            usage = getattr(resp, "usage", None)
            pt = int(getattr(usage, "prompt_tokens", 0) or 0)
            ct = int(getattr(usage, "completion_tokens", 0) or 0)
            cost = self._cost(lt, resp)
            self.calls += 1
            self.prompt_tokens += pt
            self.completion_tokens += ct
            self.cost_usd += cost
            response = {"id": getattr(resp, "id", None), "model": getattr(resp, "model", None),
                        "choices": [{"text": t, "finish_reason": f} for t, f in zip(texts, finish)],
                        "usage": {"prompt_tokens": pt, "completion_tokens": ct}}
            self._record(kw, messages, key, text_key, response, cost, latency, attempt)
            log.info("VLM %s: %d answer(s), %d+%d tokens, $%.4f, %.1fs", self.model, len(texts), pt, ct, cost,
                     latency)
            return texts

    def _wait(self, exc, attempt: int) -> float:
        wait = self.retry_wait * (2 ** (attempt - 1))
        headers = getattr(getattr(exc, "response", None), "headers", None) or {}
        try:
            after = float(headers.get("retry-after"))
            wait = max(wait, min(after, 60.0))
        except (TypeError, ValueError, AttributeError):
            pass
        return wait

    def _cost(self, lt, resp) -> float:
        try:
            return float(lt.completion_cost(completion_response=resp) or 0.0)
        except Exception:  # noqa: BLE001 - unknown or local model: no price, count 0
            if not self._unpriced_warned:
                log.info("VLM %s: LiteLLM has no price for this model; counting its cost as $0", self.model)
                self._unpriced_warned = True
            return 0.0

    def _record(self, kw, messages, key, text_key, response, cost, latency, attempt, error=None) -> None:
        if self.recorder is None:
            return
        params = {k: v for k, v in kw.items() if k not in ("messages", "model", "api_base")}
        record = {"v": RECORD_VERSION, "time": datetime.now(UTC).isoformat(timespec="seconds"),
                  "model": self.model, "provider": self.provider, "key": key, "text_key": text_key,
                  "request": {"params": params, "api_base": _safe_url(self.api_base)},
                  "response": response, "cost_usd": cost, "latency_s": round(latency, 3), "attempt": attempt,
                  "error": error}
        try:
            self.recorder.write(record, messages)
        except OSError as exc:
            log.warning("cannot append to VLM recording %s: %s", self.recorder.path, exc)


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
            lines = self.path.read_text(encoding="utf-8").splitlines()
        except OSError as exc:
            raise VLMConfigError(f"replay:{path}: cannot read the recording ({exc.strerror or exc})") from None
        self.records: list[dict] = []
        for lineno, line in enumerate(lines, start=1):
            if not line.strip():
                continue
            try:
                rec = json.loads(line)
            except json.JSONDecodeError:
                log.warning("replay %s:%d: not JSON, skipped", path, lineno)
                continue
            if rec.get("error") or not rec.get("response"):
                continue
            self.records.append(rec)
        if not self.records:
            raise VLMConfigError(f"replay:{path}: the recording holds no answered calls")
        models = sorted({r.get("model", "?") for r in self.records})
        self.model = models[0] if len(models) == 1 else "+".join(models)
        self.name = f"replay:{path}"
        self._entries: list[tuple[int, str]] = []  # (record index, text)
        self._by_key: dict[str, list[int]] = {}
        self._by_text: dict[str, list[int]] = {}
        for i, rec in enumerate(self.records):
            for choice in rec["response"].get("choices", []):
                e = len(self._entries)
                self._entries.append((i, choice.get("text", "")))
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
        return [self._entries[e][1] for e in picked]


# --------------------------------------------------------------------------------------------
# proposal schema and validation
# --------------------------------------------------------------------------------------------
_TYPE_ALIASES = {"circle": "disc", "disk": "disc", "ball": "disc", "rectangle": "box", "rect": "box",
                 "square": "box", "aabb": "box"}


def _normalise_region(d: Any) -> Any:
    if not isinstance(d, dict):
        return d
    d = dict(d)
    if "centre" in d and "center" not in d:
        d["center"] = d.pop("centre")
    if "r" in d and "radius" not in d:
        d["radius"] = d.pop("r")
    if "cx" in d and "cy" in d and "center" not in d:
        d["center"] = [d.pop("cx"), d.pop("cy")]
    if all(k in d for k in ("xmin", "ymin", "xmax", "ymax")) and "min" not in d:
        d["min"] = [d.pop("xmin"), d.pop("ymin")]
        d["max"] = [d.pop("xmax"), d.pop("ymax")]
    kind = d.get("type")
    if isinstance(kind, str):
        kind = kind.strip().lower()
        d["type"] = _TYPE_ALIASES.get(kind, kind)
    elif kind is None:
        d["type"] = "disc" if "radius" in d else "box" if "min" in d else None
    return d


class _Strict(BaseModel):
    model_config = ConfigDict(extra="ignore", allow_inf_nan=False)


class DiscSpec(_Strict):
    type: Literal["disc"]
    center: tuple[float, float]
    radius: float = Field(gt=0)

    def to_region(self) -> Region:
        return Disc(self.center[0], self.center[1], self.radius)


class BoxSpec(_Strict):
    type: Literal["box"]
    min: tuple[float, float]
    max: tuple[float, float]

    @model_validator(mode="after")
    def _ordered(self):
        if not (self.max[0] > self.min[0] and self.max[1] > self.min[1]):
            raise ValueError("box needs max > min in both x and y")
        return self

    def to_region(self) -> Region:
        return Box(self.min[0], self.min[1], self.max[0], self.max[1])


RegionSpec = Annotated[DiscSpec | BoxSpec, Field(discriminator="type"), BeforeValidator(_normalise_region)]


class SplitProposal(_Strict):
    """One edge-split candidate: waypoint regions x1..x_{k-1}, visited in order between u and v."""

    reasoning: str = ""
    waypoints: list[RegionSpec] = Field(min_length=1)


class VertexSpec(_Strict):
    name: str = Field(min_length=1)
    region: RegionSpec | None = None
    refines: str | None = None


class EdgeSpec(_Strict):
    u: str
    v: str

    @model_validator(mode="before")
    @classmethod
    def _aliases(cls, d):
        if isinstance(d, dict):
            d = dict(d)
            for a, b in (("from", "u"), ("to", "v"), ("source", "u"), ("target", "v")):
                if a in d and b not in d:
                    d[b] = d.pop(a)
        elif isinstance(d, (list, tuple)) and len(d) == 2:
            d = {"u": d[0], "v": d[1]}
        return d


class GraphProposal(_Strict):
    """A whole task graph (the one-shot VLM baseline)."""

    reasoning: str = ""
    vertices: list[VertexSpec] = Field(min_length=1)
    edges: list[EdgeSpec] = Field(min_length=1)
    initial: str
    finals: list[str] = Field(min_length=1)


def region_json(region: Region, digits: int = 3) -> dict:
    """A region in the answer schema's JSON form (unions as ``{"type": "union", "members": [...]}``)."""
    r = lambda v: round(float(v), digits)  # noqa: E731
    if isinstance(region, Disc):
        return {"type": "disc", "center": [r(region.cx), r(region.cy)], "radius": r(region.r)}
    if isinstance(region, Box):
        return {"type": "box", "min": [r(region.xmin), r(region.ymin)], "max": [r(region.xmax), r(region.ymax)]}
    return {"type": "union", "members": [region_json(m, digits) for m in region.parts()]}


def parse_json(text: str | None) -> Any:
    """The JSON object in a reply: bare, in a ```json fence, or the outermost {...}; else ProposalRejected."""
    if not text or not text.strip():
        raise ProposalRejected("empty reply")
    candidates = [text.strip()]
    fence = re.search(r"```(?:json|JSON)?\s*(.*?)```", text, re.DOTALL)
    if fence:
        candidates.append(fence.group(1).strip())
    lo, hi = text.find("{"), text.rfind("}")
    if 0 <= lo < hi:
        candidates.append(text[lo:hi + 1])
    err = None
    for c in candidates:
        try:
            return json.loads(c)
        except json.JSONDecodeError as exc:
            err = exc
    raise ProposalRejected(f"reply is not valid JSON ({err.msg} at line {err.lineno} column {err.colno})")


def _schema_reason(exc: ValidationError) -> str:
    errs = exc.errors()
    parts = []
    for e in errs[:2]:
        loc = ".".join(str(x) for x in e.get("loc", ())) or "reply"
        parts.append(f"{loc}: {e.get('msg', 'invalid')}")
    more = f" (+{len(errs) - 2} more)" if len(errs) > 2 else ""
    return "reply does not follow the schema: " + "; ".join(parts) + more


def check_region(region: Region, maze, what: str = "waypoint") -> str | None:
    """Why ``region`` is unusable as a waypoint in ``maze`` (None if it is fine)."""
    c = np.asarray(region.centre(), dtype=float)
    x0, y0, x1, y1 = maze.bounds()
    size = max(maze.width, maze.height)
    tiny = 0.01 * maze.cell_size
    if not np.all(np.isfinite(c)):
        return f"{what} has a non-finite centre"
    if not (x0 <= c[0] <= x1 and y0 <= c[1] <= y1):
        return (f"{what} centre ({c[0]:.3g}, {c[1]:.3g}) lies outside the maze "
                f"(x in [{x0:g}, {x1:g}], y in [{y0:g}, {y1:g}])")
    if bool(maze.walls.contains(c)):
        row, col = (int(v) for v in maze.xy_to_cell(c))
        return f"{what} centre ({c[0]:.3g}, {c[1]:.3g}) lies inside a wall (cell row {row}, col {col})"
    if isinstance(region, Disc):
        if region.r > size:
            return f"{what} radius {region.r:.3g} is larger than the maze ({size:g})"
        if region.r < tiny:
            return f"{what} radius {region.r:.3g} is below 1% of a cell ({tiny:g})"
    elif isinstance(region, Box):
        w, h = region.xmax - region.xmin, region.ymax - region.ymin
        if max(w, h) > size:
            return f"{what} box side {max(w, h):.3g} is larger than the maze ({size:g})"
        if min(w, h) < tiny:
            return f"{what} box side {min(w, h):.3g} is below 1% of a cell ({tiny:g})"
    return None


def parse_split(text: str | None, maze, *, max_waypoints: int = 32) -> tuple[list[Region], str]:
    """Validate one edge-split reply: ``(waypoint regions, reasoning)`` or ProposalRejected."""
    data = parse_json(text)
    if isinstance(data, list):  # a bare list of waypoints
        data = {"waypoints": data}
    try:
        prop = SplitProposal.model_validate(data)
    except ValidationError as exc:
        raise ProposalRejected(_schema_reason(exc)) from None
    if len(prop.waypoints) > max_waypoints:
        raise ProposalRejected(f"{len(prop.waypoints)} waypoints is more than the limit of {max_waypoints}")
    regions = []
    for i, spec in enumerate(prop.waypoints, start=1):
        region = spec.to_region()
        why = check_region(region, maze, f"waypoint {i}")
        if why:
            raise ProposalRejected(why)
        regions.append(region)
    return regions, prop.reasoning


def parse_graph(text: str | None, maze, original, *, max_vertices: int = 40):
    """Validate a one-shot whole-graph reply against ``maze`` and the ``original`` TaskGraph.

    Returns ``(TaskGraph, reasoning)``.  Vertices that keep an original vertex (``refines`` = its
    name, or the same name with ``refines`` null) keep that name and, if ``region`` is null, its
    set; all others are intermediates (``refines=None``).  Edges get the avoid set of the original
    edge they lie on (or the union of the original avoid sets) and, where a chain of
    intermediates joins original vertices ``u -> v`` that the original links, ``parent=(u, v)``.
    No refinement guarantee is implied (the paper's baseline has none).
    """
    from .graph import TaskGraph, infer_parents
    from .regions import union

    data = parse_json(text)
    try:
        prop = GraphProposal.model_validate(data)
    except ValidationError as exc:
        raise ProposalRejected(_schema_reason(exc)) from None
    if len(prop.vertices) > max_vertices:
        raise ProposalRejected(f"{len(prop.vertices)} vertices is more than the limit of {max_vertices}")
    og = original.g
    names = [v.name for v in prop.vertices]
    dup = {n for n in names if names.count(n) > 1}
    if dup:
        raise ProposalRejected(f"vertex name(s) used twice: {', '.join(sorted(dup))}")
    tg = TaskGraph(original.initial)
    rename: dict[str, str] = {}
    kept: set[str] = set()
    for i, vs in enumerate(prop.vertices):
        orig = vs.refines if vs.refines is not None else (vs.name if vs.name in og else None)
        if orig is not None and orig not in og:
            raise ProposalRejected(f"vertex {vs.name!r} refines {orig!r}, which is not a vertex of the original graph")
        if vs.region is None and orig is None:
            raise ProposalRejected(f"new vertex {vs.name!r} needs a region")
        region = og.nodes[orig]["region"] if vs.region is None else vs.region.to_region()
        if vs.region is not None:
            why = check_region(region, maze, f"vertex {vs.name!r}")
            if why:
                raise ProposalRejected(why)
        if orig is not None and orig not in kept:
            name = orig
            kept.add(orig)
        elif vs.name not in og and vs.name not in tg.g and vs.name not in rename.values():
            name = vs.name
        else:
            name = f"x{i}" if f"x{i}" not in og and f"x{i}" not in tg.g else tg.fresh_name()
        rename[vs.name] = name
        tg.add_vertex(name, region, refines=orig, label=vs.name, point=og.nodes[orig]["point"]
                      if orig is not None and vs.region is None else None)
    for who, what in ((prop.initial, "initial"), *((f, "final") for f in prop.finals)):
        if who not in rename:
            raise ProposalRejected(f"{what} vertex {who!r} is not among the vertices")
    initial = rename[prop.initial]
    if tg.g.nodes[initial]["refines"] != original.initial:
        raise ProposalRejected(f"the initial vertex must keep the original start {original.initial!r}")
    finals = {rename[f] for f in prop.finals}
    for f in finals:
        if tg.g.nodes[f]["refines"] not in original.finals:
            goals = ", ".join(sorted(original.finals))
            raise ProposalRejected(f"final vertex {f!r} must keep an original final vertex ({goals})")
    avoids = {}
    for _, _, d in og.edges(data=True):
        avoids[json.dumps(d["avoid"].to_dict(), sort_keys=True)] = d["avoid"]
    all_avoid = union(list(avoids.values()))
    pairs = []
    for es in prop.edges:
        for end in (es.u, es.v):
            if end not in rename:
                raise ProposalRejected(f"edge {es.u}->{es.v} uses unknown vertex {end!r}")
        a, b = rename[es.u], rename[es.v]
        if a == b:
            raise ProposalRejected(f"edge {es.u}->{es.v} is a self-loop")
        if (a, b) not in pairs:
            pairs.append((a, b))
    import networkx as nx

    probe = nx.DiGraph(pairs)
    if not nx.is_directed_acyclic_graph(probe):
        raise ProposalRejected("the edges contain a cycle (a task graph must be acyclic)")
    tg.initial = initial

    for a, b in pairs:
        tg.add_edge(a, b, all_avoid)
    infer_parents(tg, original)  # the original edge each chain of new waypoints implements
    for _, _, d in tg.g.edges(data=True):
        if og.has_edge(*d["parent"]):
            d["avoid"] = og.edges[d["parent"]]["avoid"]
    reach = nx.descendants(tg.g, initial) | {initial}
    if not finals & reach:
        raise ProposalRejected("no final vertex is reachable from the initial vertex")
    tg.finals = finals
    return tg, prop.reasoning
