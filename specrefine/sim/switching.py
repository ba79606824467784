"""When a compositional policy's goal policy is fed the next leg's goal point: the named switching rules.

* ``at-region`` (the paper's, the default): on entering a leg's goal region the policy is fed the next leg's goal
  point at once.
* ``slow-turn`` (beyond the paper; docs/ant_experiments.md section 6): at the start of every leg (a goal switch,
  or an evaluation started from a preceding leg's end states), while the torso's planar speed exceeds
  :attr:`SlowTurn.speed` and its velocity points more than :attr:`SlowTurn.turn_deg` away from the line to the
  leg's goal point, for at most :attr:`SlowTurn.max_hold` decisions, the policy is fed its own position as the
  goal (it brakes); from the first decision where any of the three fails, the leg's goal point, for the rest of
  the leg.  A leg's goal region, avoid set and horizon are unchanged: the hold is spent from the leg's horizon.

A rule only changes what the policy aims at; where a leg ends, and how an episode fails, stay the evaluator's.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..core.errors import SpecrefineError

AT_REGION, SLOW_TURN = "at-region", "slow-turn"
SWITCHING = (AT_REGION, SLOW_TURN)


@dataclass(frozen=True)
class SlowTurn:
    """The ``slow-turn`` rule's hold (module docstring); parameters fixed before its checks ran."""

    speed: float = 1.0  # m/s: the torso's planar speed below which the turn is taken
    turn_deg: float = 45.0  # degrees between the velocity and the line to the goal that count as a turn
    max_hold: int = 20  # decisions (1 s for the Ant) at most spent braking per leg

    def holding(self, velocity, to_goal, decisions_in_leg) -> np.ndarray:
        """Per row: the hold goes on at this decision (``velocity``, ``to_goal``: (n, 2); ``decisions_in_leg``: (n,)).
        Only a hold that has gone on since the leg began may go on (the caller keeps that flag)."""
        velocity, to_goal = np.asarray(velocity, dtype=float), np.asarray(to_goal, dtype=float)
        speed = np.linalg.norm(velocity, axis=1)
        cos = (velocity * to_goal).sum(axis=1) / np.maximum(speed * np.linalg.norm(to_goal, axis=1), 1e-12)
        return (speed > self.speed) & (cos < np.cos(np.radians(self.turn_deg))) & \
            (np.asarray(decisions_in_leg) < self.max_hold)

    def describe(self) -> str:
        return (f"slow-turn: at the start of each leg, while the torso moves faster than {self.speed:g} m/s at more "
                f"than {self.turn_deg:g} degrees from the line to the leg's goal point (at most {self.max_hold} "
                "decisions), the policy aims at its own position (it brakes), then at the leg's goal point")


def switching_rule(name: str) -> SlowTurn | None:
    """The rule named ``name``: None for ``at-region`` (nothing held), else its hold."""
    if name == AT_REGION:
        return None
    if name == SLOW_TURN:
        return SlowTurn()
    raise SpecrefineError(f"switching rule {name!r:.40}: expected one of {', '.join(SWITCHING)}")
