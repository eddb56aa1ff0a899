"""Backlash between the handwheel and the rack (pinion mesh), as a dead band of the column (a candidate).

Signature: the rack position against the handwheel angle jumps by 2b whenever the torque
changes sign; the torque against the (measured) rack does not change, the torque against
the handwheel angle has a flat step at zero torque 2b * G wide.

Strength b: the lash in rack travel (m, 0 = the paper's model), a dead band of the column twist; it fills the
column_deflection slot and adds no coordinate. The derivation, its reasoning and its sources: docs/model.md, "Rack
lash (`rack_lash`)".
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
