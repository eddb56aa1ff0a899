"""Pre-sliding, history-dependent friction of the rack (a bristle of the Dahl kind): a rival of the tanh friction.

Strength F_d (N, 0 = absent): the extra Coulomb force of steady sliding, reached within about the pre-sliding
displacement x_p (m) of rack travel after a reversal. It adds one coordinate, the bristle's root along the rack axis
(m). The derivation, its reasoning and its sources: docs/model.md, "Rack pre-sliding (`rack_presliding`)".
"""

from __future__ import annotations

from ..lazy_sympy import me, sp

from ....parameters import Quantity
from ..components import Effect, Rival
from ..system import action_reaction


class RackPresliding(Effect):
    name = "rack_presliding"
    description = (
        "Pre-sliding rack friction: a bristle (spring F_d / x_p in series with a slider of force F_d) between "
        "rack and housing; one root coordinate; 0 = absent"
    )
    in_default_set = False
    rival = Rival(closest="rack_stiction", related=("column_friction", "kingpin_friction"),
                  why="rack friction departing from the tanh law near each reversal; rack_stiction's excess lives "
                      "at low speed, the bristle's in the first tenths of a millimetre of travel",
                  probe_strength=100.0)
    quantities = (
        Quantity("rack_presliding.force", "N", 0.0, 2000.0, lower_inclusive=True, default=0.0,
                 source="candidate: rival of the tanh rack friction, a pre-sliding (Dahl-type) rack friction force "
                        "F_d added to the tanh rack friction; chosen, 0 = absent"),
        Quantity("rack_presliding.presliding_displacement", "m", 1.0e-6, 0.01, lower_inclusive=True, default=2.0e-4,
                 source="choice: pre-sliding displacement x_p of the rack's bristle (0.2 mm; steel-on-polymer "
                        "contacts show 0.01-1 mm)"),
        Quantity("rack_presliding.slip_smoothing", "s/m", 10.0, 1.0e6, lower_inclusive=True, default=10000.0,
                 source="choice: tanh smoothing of the bristle's slider; ten times the rack friction's, so the "
                        "slider slides fully at 0.1 mm/s"),
        Quantity("rack_presliding.node_mass", "kg", 1.0e-4, 10.0, lower_inclusive=True, default=0.01,
                 source="choice: mass of the bristle root, small so that its time sqrt(m x_p / F_d) is below 0.1 ms "
                        "at 100 N"),
        Quantity("rack_presliding.damping_ratio", "1", 0.0, 10.0, lower_inclusive=True, default=1.0,
                 source="choice: damping ratio of the root's mode on the bristle, a damper 2 zeta sqrt(k m) in "
                        "parallel with the spring (the bristle damping of the LuGre model); the mode exists only "
                        "because the root has a mass, and critical damping ends its oscillation within a period; "
                        "the damper's force is zero in steady sliding and vanishes with the node mass"),
    )
    uses = ("rack_presliding.force", "rack_presliding.presliding_displacement", "rack_presliding.slip_smoothing",
            "rack_presliding.node_mass", "rack_presliding.damping_ratio")

    def configure(self, model):
        model.state(self).root = model.add_coordinate("bristle_root", "m", owner=self.name)

    def bodies(self, model):
        k, state = model.kinematics, model.state(self)
        q, u = state.root
        root = k.rack_housing_point.locatenew("bristle_root", (q - model.rack_q) * k.B.y)
        root.set_vel(k.B, u * k.B.y)
        root.v1pt_theory(k.rack_housing_point, model.N, k.B)
        state.point = root
        return [me.Particle("bristle_root", root, model.p("rack_presliding.node_mass"))]

    def _stiffness(self, model):
        """The bristle's stiffness k = F_d / x_p."""
        return model.p("rack_presliding.force") / model.p("rack_presliding.presliding_displacement")

    def _spring_force(self, model):
        q, _ = model.state(self).root
        return self._stiffness(model) * (model.rack_q - q)

    def loads(self, model):
        k, state = model.kinematics, model.state(self)
        _, u = state.root
        # spring and damper in parallel, the damper on the bristle's deformation rate (rack speed less root speed)
        damping = 2 * model.p("rack_presliding.damping_ratio") * sp.sqrt(
            self._stiffness(model) * model.p("rack_presliding.node_mass"))
        bristle = self._spring_force(model) + damping * (model.rack_u - u)
        slider = model.p("rack_presliding.force") * sp.tanh(model.p("rack_presliding.slip_smoothing") * u)
        return (action_reaction(k.rack_point, -bristle * k.B.y, state.point)
                + action_reaction(state.point, -slider * k.B.y, k.rack_housing_point))

    def potential_energy(self, model):
        q, _ = model.state(self).root
        return self._stiffness(model) * (model.rack_q - q) ** 2 / 2


EFFECT = RackPresliding()
