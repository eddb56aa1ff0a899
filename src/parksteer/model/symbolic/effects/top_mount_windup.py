"""Elastic wind-up of the strut top mount and road spring about the king-pin axis: a centring spring (a rival).

Physics. On a MacPherson strut the whole strut turns with the wheel about the king-pin axis: its
upper end turns in the top mount (rubber, often with a bearing) and the coil spring's seats turn
with it or wind the spring up. Both resist steering elastically, a centring torque about the
axis that grows with the steer angle and returns its energy on the way back. The paper's model
has none (its steering assembly turns freely about the axis). Model: at each wheel a torsion
spring about the steer axis between the steering assembly and the body,

    T = -k_tm delta,   energy k_tm delta^2 / 2,

delta the wheel's steer angle; k_tm (N m/rad per wheel, 0 = absent) is chosen, not measured.

Signature against the rack: conservative and odd in the rack, like lifting (no hysteresis:
it adds on the way out and gives back on the way in, both shares cross zero at the centre), and
nearly linear in the steer angle, as lifting's torque is near the centre. What separates it from lifting
is load and offset: it does not depend on the wheel load (it is the same unladen and part laden)
nor on the spacer offset, whereas lifting's torque is proportional to the wheel load and grows
with the offset. Provenance: a candidate beyond the paper.
"""

from __future__ import annotations

from ....names import SIDES
from ....parameters import Quantity
from ..components import Effect, Rival
from ..system import torque_between


class TopMountWindup(Effect):
    name = "top_mount_windup"
    description = (
        "Centring torque of the strut top mount and spring wind-up about each king-pin axis, -k_tm * steer angle; "
        "0 = absent"
    )
    in_default_set = False
    rival = Rival(closest=None, related=(),
                  why="an elastic centring torque about the king-pin axis; the only conservative rack-position term "
                      "of the model is lifting, which is in the base model, not a candidate",
                  probe_strength=30.0)
    quantities = (
        Quantity("top_mount_windup.stiffness", "N m/rad", 0.0, 1000.0, lower_inclusive=True, default=0.0,
                 source="candidate: torsional stiffness about the king-pin axis of each strut's top-mount rubber "
                        "and road-spring wind-up; not given by the paper, chosen 0-100 N m/rad per wheel (50 N "
                        "m/rad gives 28 N m per wheel at the 0.56 rad lock, about 2.7 N m at the handwheel for "
                        "both, the size of the lifting torque); 0 = absent"),
    )
    uses = ("top_mount_windup.stiffness",)

    def loads(self, model):
        k = model.kinematics
        stiffness = model.p("top_mount_windup.stiffness")
        out = []
        for side in SIDES:
            # between the steered assembly and the body (the axis frame is fixed in it)
            out += torque_between(-stiffness * k.steer_angle[side], k.axis_frame[side].z, k.steer_frame[side],
                                  k.axis_frame[side])
        return out

    def potential_energy(self, model):
        k = model.kinematics
        return sum(model.p("top_mount_windup.stiffness") * k.steer_angle[side] ** 2 / 2 for side in SIDES)


EFFECT = TopMountWindup()
