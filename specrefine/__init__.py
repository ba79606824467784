"""specrefine: VLM-proposed, symbolically tuned refinement of reach-avoid task specifications."""

__version__ = "0.1.0"

from .notebook import record  # noqa: E402  (notebooks: `from specrefine import record`)

__all__ = ["record", "__version__"]
