"""Fingerprint of the twin's numbers, for refactors that must keep every number bit-identical.

    python .ci/fingerprint.py before.json     # on the old commit
    python .ci/fingerprint.py after.json      # on the new one
    cmp before.json after.json

Hashes the traces and metrics of every plant preset x controller x trajectory (seed 3), payloads in
both orientations, a changed supply and PWM period, noise off
the dm_control environment (two
tasks, seeded random actions)
and the live joint (targets, a trajectory, a controller switch).
About 10 s. The CLI's tables (CSV) are checked separately by running the same commands on both.
"""
import hashlib
import json
import sys

import numpy as np

from twin.envs import environment as envmod
from twin.envs import live, runner
from twin.physics import model
from twin.plants import PLANTS
from twin.sim.scenario import Scenario

out = {}
def h(*arrays):
    m = hashlib.sha256()
    for a in arrays:
        m.update(np.ascontiguousarray(np.asarray(a, dtype=float)).tobytes())
    return m.hexdigest()[:16]

names = list(PLANTS)
scs = []
for p in names:
    for c in ("pva", "ffpva", "smc"):
        for t in (1, 2, 3, 4):
            scs.append(Scenario(c, t, plant=p, seed=3))
for p in ("thesis", "as-built"):
    for c in ("ffpva", "smc"):
        for o in model.Orientation:
            scs.append(Scenario(c, 1, plant=p, payload=6.5e-3, orientation=o, seed=1))
scs.append(Scenario("smc", 3, plant="as-built", supply_pressure=250e3, pwm_period=20e-3, seed=2))
scs.append(Scenario("ffpva", 2, plant="thesis", noise=False))
# run per plant so batches are as the CLI would make them, plus one mixed batch
for r in runner.run_many(scs):
    tr = r.trace
    key = f"{r.scenario.plant_name}/{r.scenario.controller}/T{r.scenario.trajectory}/{r.scenario.payload}/{r.scenario.orientation.value}/{r.scenario.seed}"
    out["run " + key] = h(tr.angle, tr.rack_position, tr.measured_position, tr.duty, tr.valve_open, tr.pressure_a,
                           tr.pressure_b, tr.supply_pressure, tr.tooth_force_spur, tr.tooth_force_rack_a,
                           tr.tooth_force_rack_b, [r.metrics.rmse, r.metrics.sse, r.metrics.max_error]) + " " + repr(r.warnings)
for r in runner.run_many([Scenario("ffpva", 1, plant="as-built", seed=s) for s in range(3)]):
    out[f"single-batch as-built ffpva T1 seed {r.scenario.seed}"] = h(r.trace.angle, r.trace.duty)

# dm_control env
for plant_name in ("thesis", "as-built"):
    env = envmod.load("track", trajectory=1, seed=4, plant=plant_name)
    rng = np.random.default_rng(0)
    obs_hash = hashlib.sha256()
    for _episode in range(2):
        ts = env.reset()
        while not ts.last():
            for v in ts.observation.values():
                obs_hash.update(np.asarray(v, float).tobytes())
            ts = env.step([rng.uniform(-60, 60)])
            obs_hash.update(np.float64(ts.reward).tobytes())
    out[f"env {plant_name}"] = obs_hash.hexdigest()[:16]
env = envmod.load("hold", seed=7, action_period=1e-3)
ts = env.reset()
acc = hashlib.sha256()
rng = np.random.default_rng(1)
for _ in range(600):
    ts = env.step([rng.uniform(-100, 100)])
    for v in ts.observation.values():
        acc.update(np.asarray(v, float).tobytes())
out["env hold"] = acc.hexdigest()[:16]

# live joint
for plant_name in ("thesis", "as-built"):
    j = live.LiveJoint(Scenario("smc", 4, plant=plant_name, seed=5))
    rs = []
    j.advance(1.0)
    rs.append(j.readout())
    j.set_target(1.0)
    j.advance(0.7)
    rs.append(j.readout())
    j.switch_controller("ffpva")
    j.play(3)
    j.advance(1.3)
    rs.append(j.readout())
    out[f"live {plant_name}"] = h([[r.time, r.angle, r.desired_angle, r.duty, r.pressure_a, r.pressure_b, r.supply_pressure, *r.valve_open] for r in rs])

json.dump(out, open(sys.argv[1], "w"), indent=1, sort_keys=True)
print(len(out), "entries")
