"""Backlash between the handwheel and the rack (pinion mesh), as a dead band of the column (a candidate).

Formulation. The column is massless in the paper's model, so everything between the
prescribed handwheel and the rack (column spring and damper, Hooke joint, pinion) is a
chain of massless elements, and a lash anywhere in that chain acts like a lash in series
with the column spring: the chain carries no torque until the lash is taken up. A lash of
+-b of rack travel is therefore a dead band of +-b * handwheel_to_rack_ratio in the column
twist (handwheel minus column angle), at the mean pinion ratio (the Hooke joint's speed
ratio, 0.90-1.11, scales the band seen at the rack by as much). The column's spring and
damper act on the deflection

    g(x) = phi(x - a) - phi(-x - a),  phi(z) = (z + sqrt(z^2 + e^2)) / 2,  a = b G, e = w G,

a dead zone smoothed over the width w (the hyperbola phi is a smooth max(z, 0)); the
column torque is (k g + c dg/dt) dg/dx (the column_deflection slot of ModelSpace). No coordinate is
added and nothing is stiffer than the engaged column, so the integrator sees the paper's
stiffness when the lash is taken up and a free rack while it is crossed. At b = 0, g(x) = x
exactly and the model is the paper's.

Signature: the rack position against the handwheel angle jumps by 2b whenever the torque
changes sign; the torque against the (measured) rack does not change, the torque against
the handwheel angle has a flat step at zero torque 2b * G wide.
"""

from __future__ import annotations

from ..lazy_sympy import sp

from ....parameters import Quantity
from ..components import Effect


class RackLash(Effect):
    name = "rack_lash"
    description = (
        "Backlash of +-b of rack travel between handwheel and rack (pinion mesh), as a smoothed dead band of the "
        "column twist, +-b * handwheel_to_rack_ratio; 0 = absent"
    )
    in_default_set = False
    quantities = (
        Quantity("rack_lash.lash", "m", 0.0, 0.005, lower_inclusive=True, default=0.0,
                 source="candidate: half the free play of the rack-and-pinion mesh, as rack travel; a worn or badly "
                        "adjusted rack has 0-0.5 mm (0-5.4 degrees at the handwheel through 186.47 rad/m); 0 = "
                        "absent"),
        Quantity("rack_lash.smoothing_width", "m", 1.0e-7, 0.001, lower_inclusive=True, default=1.0e-5,
                 source="candidate: rack travel over which the tooth contact takes up the load (the dead band's "
                        "corners are rounded over it); 0.01 mm keeps the corners sharp beside a lash of 0.1-0.5 mm "
                        "and the residual stiffness in the band below 0.1 % of the column's"),
    )
    uses = ("steering.handwheel_to_rack_ratio", "rack_lash.lash", "rack_lash.smoothing_width")
    replaces = "column_deflection"

    def deflection(self, model, twist):
        ratio = model.p("steering.handwheel_to_rack_ratio")
        band, width = model.p("rack_lash.lash") * ratio, model.p("rack_lash.smoothing_width") * ratio

        def smooth_max0(z):
            return (z + sp.sqrt(z**2 + width**2)) / 2

        return smooth_max0(twist - band) - smooth_max0(-twist - band)


EFFECT = RackLash()
