"""The VLM client side: chat messages, one LiteLLM client for any provider, record and replay.

What is asked (prompts) and how answers become proposals live in :mod:`specrefine.proposers`.
"""

from ..core.errors import ProposalRejected, ReplayMiss, VLMConfigError, VLMError, VLMUnavailable
from .client import LiteLLMClient
from .messages import (
    MAX_REPLY_CHARS,
    BadReply,
    VLMClient,
    build_content,
    image_part,
    messages_to_text,
    one_line,
    request_hash,
    scrub,
    text_part,
)
from .recording import Recorder, ReplayClient, default_record_path

__all__ = [
    "MAX_REPLY_CHARS", "BadReply", "LiteLLMClient", "ProposalRejected", "Recorder", "ReplayClient", "ReplayMiss",
    "VLMClient", "VLMConfigError", "VLMError", "VLMUnavailable", "build_content", "default_record_path", "image_part",
    "messages_to_text", "one_line", "request_hash", "scrub", "text_part",
]
