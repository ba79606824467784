"""specrefine: VLM-proposed, symbolically tuned refinement of reach-avoid task specifications."""

from .experiment import Experiment, setup

__version__ = "0.1.0"
__all__ = ["Experiment", "setup"]
