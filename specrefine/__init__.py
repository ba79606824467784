"""specrefine: VLM-proposed, symbolically tuned refinement of reach-avoid task specifications."""

__version__ = "0.1.0"
