"""The step log's one-line descriptions (notebooks 05 and 07, the slider's titles)."""

from __future__ import annotations

from specrefine.runs.explore import describe


def test_the_correction_steps_read_as_sentences():
    check = {"step": 4, "event": "correct-check", "path": ["S", "a", "G"], "p": 0.8, "probabilities": [1.0, 0.8],
             "correct_pass": 2}
    assert describe(check) == "step 4: check the path on fresh rollouts (pass 2): p = 0.800 over 2 legs"
    leg = {"step": 5, "event": "correct-leg", "leg": 1, "edge": ["a", "G"], "p_leg": 0.8, "p_window": 0.8,
           "tried": [{"kind": "bypass", "p_window": 0.5}, {"kind": "split", "p_window": 0.95}], "accepted": "split"}
    assert describe(leg) == ("step 5: correct leg 1 (a -> G, fresh p 0.800, window 0.800): tried bypass 0.500, "
                             "split 0.950; accepted split")
    advanced = dict(leg, p_leg=0.0, p_window=0.0, accepted="advance",
                    tried=[{"kind": "split", "p_window": 0.0}, {"kind": "advance", "p_window": 0.0, "nearer": 6.13}])
    assert describe(advanced).endswith("tried split 0.000, advance 0.000 (+6.13 m nearer); accepted advance")
    nothing = dict(leg, tried=[], accepted=None)
    assert describe(nothing).endswith("tried nothing; accepted none")
    done = {"step": 6, "event": "correct-done", "p": 0.95, "probabilities": [1.0, 0.95]}
    assert describe(done) == "step 6: correction done: p = 0.950 over 2 legs (on the rollouts that chose them)"
    repaired = {"step": 7, "event": "split-repaired", "edge": ["S", "G"], "legs_repaired": 2}
    assert describe(repaired) == "step 7: repair the split of S -> G: 2 leg(s) split again"


def test_an_unknown_or_incomplete_step_falls_back_to_its_event_name():
    assert describe({"step": 1, "event": "something-new"}) == "step 1: something-new"
    assert describe({"step": 2, "event": "correct-leg"}) == "step 2: correct-leg"
