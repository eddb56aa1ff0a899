"""Pre-sliding, history-dependent friction of the rack (a bristle of the Dahl kind): a rival of the tanh friction.

Physics. The paper's rack friction is Coulomb, smoothed as -F tanh(beta v): a function of the rack
speed alone, which flips sign within about 1 / beta = 1 mm/s of a reversal whatever the rack did
before. Real sliding contacts have a pre-sliding regime: after a reversal the asperities (the
"bristles") first deform elastically, the friction force grows with the displacement since the
reversal over a pre-sliding distance of the order of 0.01-1 mm, and only then does the contact slide
at the full force. The force depends on the path (the last reversal), not on the speed: Dahl's
model, dF/dt = sigma v (1 - (F / F_c) sgn v), with initial stiffness sigma and saturation F_c.

Model. One bristle between the rack and its housing: a spring k in series with a Coulomb slider of
force F_d. A new coordinate y is the position of the bristle's root along the rack axis (from the
housing, like the rack's): the spring acts between rack and root, -k (x - y), and the slider between
root and housing, -F_d tanh(beta_s dy/dt). k = F_d / x_p, with x_p the pre-sliding displacement, so
the force saturates at F_d after a rack travel of about x_p from a reversal. In the limit of a massless
root, F = k (x - y) obeys dF/dt = k dx/dt - (k / beta_s) atanh(F / F_d): the same initial stiffness and
saturation as Dahl's model with a sharper knee, and a slow creep at rest (time beta_s x_p), the smoothed
slider's residue. The root carries a small mass (``node_mass``) so that the mass matrix stays regular;
its own time sqrt(m / k) is far below the pre-sliding time. That mass makes a mode of its own, the root
oscillating on the spring at sqrt(k / m) (7,000 rad/s at 100 N), undamped while the slider slides; a
damper c = 2 zeta sqrt(k m) in parallel with the spring (``damping_ratio`` zeta, 1: the bristle damping of
the LuGre model) ends it within a period. Without it the integrator follows the oscillation, some
100,000 steps per simulated second (1.6 s for a cycle at 100 N, against 0.013 s); with it the torque moves
by at most 0.006 N m. The damper's force, c times the bristle's deformation rate, is zero in steady sliding
and vanishes with the root's mass, as the mode does. The effect adds F_d to the rack friction
(strength F_d in N, 0 = absent: then spring, damper and slider vanish and the root is a free, resting mass).

Signature against the rack: in steady sliding the bristle has slid and carries F_d exactly, like an
extra Coulomb friction of F_d; after each reversal the force changes sign over a rack travel of
about 2 x_p instead of over a speed of 1 / beta, so the torque's drop at a reversal is spread over
the first few tenths of a millimetre of travel, whatever the rack speed. Lifting is conservative and
follows the rack position, proportional to the wheel load and growing with the offset; this friction
depends on neither. Provenance: a rival beyond the paper (Dahl, 1968 and 1976; the elasto-plastic
bristle of Dupont et al., 2002); F_d and x_p are chosen, not measured.
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
