"""``twin study NAME``: the thesis's own studies, one module each, every one an
:class:`twin.experiments.base.Experiment`.

robustness  Chapter 6's protocol (SPEC §9), resumable
openloop    §4.6's open-loop validation: lags at the reversals, thesis model against a plant
ablation    the as-built preset on SPEC §8's cells with each effect switched off in turn
valve       §4.4.3's valve test on the twin's solenoid valve: R(d) against eq. 4.4.2
"""

from __future__ import annotations

from twin.experiments.studies import ablation, openloop, robustness, valve

STUDIES = {module.EXPERIMENT.name: module.EXPERIMENT for module in (robustness, openloop, ablation, valve)}
