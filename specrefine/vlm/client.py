"""One client for any vision-language model LiteLLM speaks.

:class:`LiteLLMClient` calls ``litellm.completion`` for any model string (``gpt-4o``,
``gemini/gemini-2.0-flash``, ``anthropic/claude-sonnet-4-5``, ``ollama/llava``, ...): images go as
base64 PNG data URLs, ``w`` samples per query (``n`` where the provider has it, else ``w`` calls),
JSON response format where supported, timeouts, and logged retries with back-off on rate limits, server
errors and dropped connections (a provider's ``Retry-After`` honoured up to ``MAX_RETRY_AFTER`` = 60 s).
One request, retries included, ends within ``deadline`` seconds (default 600, or
``SPECREFINE_VLM_DEADLINE``): past it the run stops with one line saying what timed out.  Tokens and
cost are counted per call (cost 0 for models LiteLLM has no price for).  Keys are read by LiteLLM from
the environment only; nothing this module writes (recordings, logs, error messages) ever contains them.
Every real call is appended to a recording (:mod:`specrefine.vlm.recording`).
"""

from __future__ import annotations

import logging
import os
import re
import time
from datetime import UTC, datetime
from pathlib import Path
from typing import Any

from ..core.errors import VLMConfigError, VLMError, VLMUnavailable
from .messages import MAX_REPLY_CHARS, TOO_LONG, VLMClient, one_line, request_hash
from .recording import RECORD_VERSION, Recorder, default_record_path

log = logging.getLogger(__name__)


_LOCAL_PROVIDERS = {"ollama", "ollama_chat", "vllm", "hosted_vllm", "lm_studio", "llamafile", "openai_like"}
_KEY_VARS = {"openai": "OPENAI_API_KEY", "gemini": "GEMINI_API_KEY", "anthropic": "ANTHROPIC_API_KEY",
             "ollama": "OLLAMA_API_BASE", "ollama_chat": "OLLAMA_API_BASE", "mistral": "MISTRAL_API_KEY",
             "groq": "GROQ_API_KEY", "openrouter": "OPENROUTER_API_KEY", "azure": "AZURE_API_KEY",
             "together_ai": "TOGETHERAI_API_KEY", "deepseek": "DEEPSEEK_API_KEY", "xai": "XAI_API_KEY"}
MAX_RETRY_AFTER = 60.0  # s: the longest wait a provider's Retry-After header gets (a longer one is cut to this)
_MODEL_HINT = "use a LiteLLM model string such as gpt-4o, gemini/gemini-2.0-flash, anthropic/claude-sonnet-4-5 " \
              "or ollama/llava"


def _litellm():
    from ..core.extras import require

    os.environ.setdefault("LITELLM_LOCAL_MODEL_COST_MAP", "True")  # never fetch the price list at import
    litellm = require("litellm", "vlm", "a litellm: proposer")

    litellm.suppress_debug_info = True
    return litellm


def _deadline(value: float | None) -> float:
    """Seconds one request may take, retries included: ``value``, else $SPECREFINE_VLM_DEADLINE, else 600."""
    text = os.environ.get("SPECREFINE_VLM_DEADLINE", "600") if value is None else value
    try:
        seconds = float(text)
    except ValueError:
        seconds = float("nan")
    if not 0 < seconds < float("inf"):
        raise VLMConfigError(f"VLM deadline {text!r} (SPECREFINE_VLM_DEADLINE): use a number of seconds > 0")
    return seconds


NOT_A_COMPLETION = "an HTTP 200 reply that is no chat completion (not JSON, or without choices)"
NO_ANSWERS = "a reply without answers (an empty choices list)"


def _not_a_completion(exc, lt) -> bool:
    """An HTTP 200 whose body is no chat completion.  LiteLLM reports an InternalServerError, as it does for a
    real 5xx or a refused connection; those carry an HTTP or transport error in the exception's cause chain
    (httpx, httpcore, an OSError, openai's APIConnectionError), a body that is no completion does not."""
    server_error = getattr(lt, "InternalServerError", None)
    if not (isinstance(server_error, type) and isinstance(exc, server_error)):
        return False
    cause, depth = exc, 0
    while cause is not None and depth < 16:
        kind = type(cause)
        if kind.__module__.split(".")[0] in ("httpx", "httpcore") or isinstance(cause, OSError) \
                or kind.__name__ in ("APIConnectionError", "APITimeoutError"):
            return False
        cause, depth = cause.__cause__ or cause.__context__, depth + 1
    return True


def _choices(resp) -> list[tuple[str, Any]]:
    """(text, finish_reason) of each choice of a completion."""
    out = []
    for choice in getattr(resp, "choices", None) or []:
        content = getattr(getattr(choice, "message", None), "content", None)
        if isinstance(content, list):  # some providers return content parts
            content = "".join(p.get("text", "") if isinstance(p, dict) else str(p) for p in content)
        out.append((content if isinstance(content, str) else "", getattr(choice, "finish_reason", None)))
    return out


def _answers(resp, n: int) -> list[tuple[str, Any, str | None]]:
    """(text as recorded, finish_reason, why it cannot be used) per answer; a reply with none is n bad ones."""
    if resp is None:
        return [("", None, NOT_A_COMPLETION)] * n
    choices = _choices(resp)
    if not choices:
        return [("", None, NO_ANSWERS)] * n
    return [(text[:MAX_REPLY_CHARS], finish, TOO_LONG if len(text) > MAX_REPLY_CHARS else None)
            for text, finish in choices]


def _retry_after(exc) -> float | None:
    """The seconds of a Retry-After header, if the failed call had one (LiteLLM keeps the provider's headers in
    ``litellm_response_headers``; its ``response`` is a stand-in without them)."""
    for headers in (getattr(exc, "litellm_response_headers", None), getattr(getattr(exc, "response", None), "headers",
                                                                            None)):
        try:
            seconds = float(headers.get("retry-after"))
        except (TypeError, ValueError, AttributeError):
            continue
        if seconds >= 0:
            return seconds
    return None


def _priced(lt, model: str) -> bool:
    try:
        info = lt.get_model_info(model)
    except Exception:  # noqa: BLE001 - unknown to LiteLLM
        return False
    return bool(info.get("input_cost_per_token") or info.get("output_cost_per_token"))


_DEFAULT_BASES = {"ollama": "http://localhost:11434", "ollama_chat": "http://localhost:11434"}
_BASE_VARS = {"openai": ("OPENAI_BASE_URL", "OPENAI_API_BASE"), "ollama_chat": ("OLLAMA_API_BASE",)}


def _endpoint(provider: str, api_base: str | None, resolved: str | None) -> str | None:
    """The address calls go to, where it is known here: ``api_base``, LiteLLM's resolution, the provider's
    ``*_API_BASE`` variable, or a local provider's default (None: the provider's own cloud address)."""
    names = (f"{provider.upper()}_API_BASE", *_BASE_VARS.get(provider, ()))
    for url in (api_base, resolved, *(os.environ.get(name) for name in names), _DEFAULT_BASES.get(provider)):
        if url:
            return _safe_url(url)
    return None


def _safe_url(url: str | None) -> str | None:
    """``url`` without any ``user:password@`` part or query string."""
    if not url:
        return url
    url = re.sub(r"//[^/@]*@", "//", url)
    return url.split("?", 1)[0]


class LiteLLMClient(VLMClient):
    """``litellm.completion`` for any model; see the module docstring."""

    def __init__(self, model: str, *, record_path: str | Path | None = None, record: bool = True,
                 api_base: str | None = None, timeout: float = 120.0, num_retries: int = 3,
                 retry_wait: float = 2.0, json_mode: bool = True, temperature: float | None = None,
                 max_tokens: int | None = None, check_env: bool = True, deadline: float | None = None):
        super().__init__()
        self.deadline = _deadline(deadline)
        self._until = float("inf")
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
            _, self.provider, _, resolved = lt.get_llm_provider(model, api_base=api_base)
        except Exception:
            raise VLMConfigError(f"unknown model litellm:{model}: LiteLLM cannot tell its provider; "
                                 f"{_MODEL_HINT}") from None
        self.endpoint = _endpoint(self.provider, api_base, resolved if isinstance(resolved, str) else None)
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
        self._until = time.monotonic() + self.deadline
        texts: list[str] = []
        for _ in range(n + 1):  # n calls at most when the provider has no `n`, plus one spare
            if len(texts) >= n:
                break
            want = n - len(texts) if self._n_ok else 1
            texts += self._call(messages, want)
        return texts[:n]

    def _kwargs(self, messages, n) -> dict:
        timeout = max(0.001, min(self.timeout, self._until - time.monotonic()))
        kw: dict[str, Any] = {"model": self.model, "messages": messages, "timeout": timeout,
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
                if _not_a_completion(exc, lt):  # a bad answer, not a failure: the proposer asks again
                    return self._answered(lt, kw, messages, (key, text_key), None, latency, attempt, n)
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
                    self._check_deadline(wait, attempt, exc)
                    log.warning("VLM %s: %s (%s); retry %d/%d in %.1fs", self.model, type(exc).__name__,
                                one_line(exc, 100), attempt, self.num_retries, wait)
                    time.sleep(wait)
                    continue
                if isinstance(exc, rate_limit):
                    raise VLMUnavailable(f"litellm:{self.model}: rate-limited by the provider after {attempt} "
                                         f"attempts; wait and rerun, or lower -w / the number of edges") from None
                if isinstance(exc, retryable):
                    where = f" at {self.endpoint}" if self.endpoint else ""
                    hint = " (is `ollama serve` running there? OLLAMA_API_BASE sets its address)" \
                        if self.provider.startswith("ollama") else ""
                    raise VLMUnavailable(f"litellm:{self.model}: provider unreachable or failing{where}{hint} "
                                         f"after {attempt} attempts ({one_line(exc, 120)})") from None
                raise VLMError(f"litellm:{self.model}: call failed: {one_line(exc, 160)}") from None
            return self._answered(lt, kw, messages, (key, text_key), resp, time.time() - t0, attempt, n)

    def _answered(self, lt, kw, messages, keys, resp, latency, attempt, n) -> list[str]:
        """Count and record a call the server answered; its answers, a BadReply for each that cannot be read."""
        answers = _answers(resp, n)
        usage = getattr(resp, "usage", None)
        pt = int(getattr(usage, "prompt_tokens", 0) or 0)
        ct = int(getattr(usage, "completion_tokens", 0) or 0)
        cost = self._cost(lt, resp) if resp is not None else 0.0
        self.calls += 1
        self.prompt_tokens += pt
        self.completion_tokens += ct
        self.cost_usd += cost
        response = {"id": getattr(resp, "id", None), "model": getattr(resp, "model", None),
                    "choices": [{"text": text, "finish_reason": finish, **({"bad": why} if why else {})}
                                for text, finish, why in answers],
                    "usage": {"prompt_tokens": pt, "completion_tokens": ct}}
        self._record(kw, messages, *keys, response, cost, latency, attempt)
        log.info("VLM %s: %d answer(s), %d+%d tokens, $%.4f, %.1fs", self.model, len(answers), pt, ct, cost, latency)
        return [self.bad(why) if why else text for text, _, why in answers]

    def _check_deadline(self, wait: float, attempt: int, exc) -> None:
        if time.monotonic() + wait >= self._until:
            source = f" from {self.endpoint}" if self.endpoint else ""
            raise VLMUnavailable(f"litellm:{self.model}: no answer within the {self.deadline:g} s deadline of one "
                                 f"request (SPECREFINE_VLM_DEADLINE){source} after {attempt} attempts; the last: "
                                 f"{type(exc).__name__} ({one_line(exc, 100)})") from None

    def _wait(self, exc, attempt: int) -> float:
        wait = self.retry_wait * (2 ** (attempt - 1))
        after = _retry_after(exc)
        return wait if after is None else max(wait, min(after, MAX_RETRY_AFTER))

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
