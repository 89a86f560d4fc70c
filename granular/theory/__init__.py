"""Analytic results the simulations are checked against.

Equation numbers refer to the thesis: A. Gjersvoll, *Simulation methods for granular gas
dynamics in periodic three-dimensional systems*, master's thesis, NTNU, 2020 ([G20]).
Conventions: k_B = 1, so temperature is energy, ``T = 2 <E_kin> / d`` per particle and
``<v_a^2> = T / m`` per velocity component.  **Every MSD here is the total over the d
dimensions**: the thesis derives one-dimensional MSDs and multiplies by 3 (2.56); divide
by ``dim`` for one component.  All functions accept NumPy arrays for ``t``.

Calling convention: the independent variable (``t``, ``lag``, ``speed``, the packing
fraction ``eta``, a ``box`` size, the temperature of a viscoelastic rate) is positional,
every other parameter keyword-only, one name per quantity across the package (``density``
the number density N/V, ``n`` the number of particles, ``restitution`` the constant xi):
``theory.haff_tau0(density=1000, radius=0.025, restitution=0.8, temperature0=0.66)``.
Each argument is checked by its name (a negative radius or D0, a NaN time: a ValueError
naming it).  The positional calls of version 0.1, and the names ``xi`` and ``starts``, still
work with a FutureWarning that spells out the new call; they are removed in 0.3.0.  The
names, their units and the values they accept: the table in docs/conventions.md.

Validity: the kinetic-theory coefficients (collision frequency, Haff's tau0, D0, gamma0)
are Enskog's, for a homogeneous gas (for xi < 1 the homogeneous cooling state) in the
Maxwellian approximation -- they neglect the non-Gaussian (Sonine a2) correction of a
granular gas, a percent-level effect for xi >= 0.5 that grows towards small xi -- and use
approximate contact values g2 (Carnahan-Starling in 3D, Henderson's in 2D), good to
about 1% up to eta = 0.4 (3D) and 0.5 (2D).

The functions live in one module per subject (``granular.theory.haff``,
``granular.theory.msd``, ...); every public name is here, in ``granular.theory``, and that is
where to import it from.
"""

from __future__ import annotations

from ._numerics import FloatOrArray
from .clustering import (
    cooling_rate,
    critical_box_size,
    shear_mode_growth,
    shear_mode_level,
    shear_viscosity,
)
from .equation_of_state import (
    compressibility_factor,
    contact_value,
    packing_fraction,
    pieprzyk_compressibility,
    wall_adsorption,
)
from .ergodicity import (
    udsbm_ergodicity_breaking,
)
from .gravity import (
    excess_chemical_potential,
    hydrostatic_density,
)
from .haff import (
    LangevinCoefficients,
    collision_frequency,
    collision_time,
    diffusion_d0,
    haff_tau0,
    haff_temperature,
    langevin_coefficients,
)
from .maxwell import (
    maxwell_boltzmann_moments,
    maxwell_boltzmann_pdf,
)
from .msd import (
    msd_ballistic,
    msd_diffusive,
    msd_granular,
    msd_langevin,
    msd_logarithmic,
)
from .rough import (
    RoughCoefficients,
    rough_coefficients,
    rough_cooling,
    rough_sheared_temperature_ratio,
    rough_temperature_ratio,
    rough_temperatures,
)
from .shear import (
    USFGrad,
    USFState,
    usf_enskog,
    usf_grad_dilute,
    usf_shear_rate,
    usf_temperature,
    usf_viscosity,
)
from .sonine import (
    driven_temperature,
    sonine_a2_cooling,
    sonine_a2_driven,
)
from .tracer import (
    tracer_contact_value,
    tracer_friction,
    tracer_langevin_coefficients,
)
from .transport import (
    YEH_HUMMER_XI,
    diffusion_infinite_system,
    enskog_diffusion,
    enskog_viscosity,
    pieprzyk_diffusion,
    speedy_diffusion,
)
from .trap import (
    barometric_density,
    gravity_mean_displacement,
    msd_trap,
    msd_trap_plateau,
    trap_position_autocorrelation,
    trap_velocity_autocorrelation,
)
from .udsbm import (
    msd_powerlaw_udsbm,
    msd_powerlaw_udsbm_asymptote,
    msd_udsbm,
    powerlaw_udsbm_increment_msd,
    powerlaw_udsbm_moments,
    udsbm_increment_msd,
    udsbm_v0_sq,
)
from .vibrated import (
    DILUTE_EXPONENT,
    WARR_HUNTLEY_JACQUES_EXPONENT,
    vibrated_bed_temperature,
    vibrated_temperature,
    wall_power,
    wall_power_leading,
)
from .viscoelastic import (
    VISCOELASTIC_C1,
    VISCOELASTIC_C2,
    AKappa,
    msd_viscoelastic,
    msd_viscoelastic_asymptote,
    msd_viscoelastic_second_order,
    viscoelastic_cooling_rate,
    viscoelastic_cooling_time,
    viscoelastic_delta,
    viscoelastic_diffusion,
    viscoelastic_langevin_coefficients,
    viscoelastic_tau0,
    viscoelastic_temperature,
    viscoelastic_temperature_second_order,
)

__all__ = [
    "DILUTE_EXPONENT",
    "VISCOELASTIC_C1",
    "VISCOELASTIC_C2",
    "WARR_HUNTLEY_JACQUES_EXPONENT",
    "YEH_HUMMER_XI",
    "AKappa",
    "FloatOrArray",
    "LangevinCoefficients",
    "RoughCoefficients",
    "USFGrad",
    "USFState",
    "barometric_density",
    "collision_frequency",
    "collision_time",
    "compressibility_factor",
    "contact_value",
    "cooling_rate",
    "critical_box_size",
    "diffusion_d0",
    "diffusion_infinite_system",
    "driven_temperature",
    "enskog_diffusion",
    "enskog_viscosity",
    "excess_chemical_potential",
    "gravity_mean_displacement",
    "haff_tau0",
    "haff_temperature",
    "hydrostatic_density",
    "langevin_coefficients",
    "maxwell_boltzmann_moments",
    "maxwell_boltzmann_pdf",
    "msd_ballistic",
    "msd_diffusive",
    "msd_granular",
    "msd_langevin",
    "msd_logarithmic",
    "msd_powerlaw_udsbm",
    "msd_powerlaw_udsbm_asymptote",
    "msd_trap",
    "msd_trap_plateau",
    "msd_udsbm",
    "msd_viscoelastic",
    "msd_viscoelastic_asymptote",
    "msd_viscoelastic_second_order",
    "packing_fraction",
    "pieprzyk_compressibility",
    "pieprzyk_diffusion",
    "powerlaw_udsbm_increment_msd",
    "powerlaw_udsbm_moments",
    "rough_coefficients",
    "rough_cooling",
    "rough_sheared_temperature_ratio",
    "rough_temperature_ratio",
    "rough_temperatures",
    "shear_mode_growth",
    "shear_mode_level",
    "shear_viscosity",
    "sonine_a2_cooling",
    "sonine_a2_driven",
    "speedy_diffusion",
    "tracer_contact_value",
    "tracer_friction",
    "tracer_langevin_coefficients",
    "trap_position_autocorrelation",
    "trap_velocity_autocorrelation",
    "udsbm_ergodicity_breaking",
    "udsbm_increment_msd",
    "udsbm_v0_sq",
    "usf_enskog",
    "usf_grad_dilute",
    "usf_shear_rate",
    "usf_temperature",
    "usf_viscosity",
    "vibrated_bed_temperature",
    "vibrated_temperature",
    "viscoelastic_cooling_rate",
    "viscoelastic_cooling_time",
    "viscoelastic_delta",
    "viscoelastic_diffusion",
    "viscoelastic_langevin_coefficients",
    "viscoelastic_tau0",
    "viscoelastic_temperature",
    "viscoelastic_temperature_second_order",
    "wall_adsorption",
    "wall_power",
    "wall_power_leading",
]

# the public names say they are granular.theory's (where the API reference lists them and
# users import them from), not the subject module's that defines them
for _name in __all__:
    _obj = globals()[_name]
    if getattr(_obj, "__module__", "").startswith(__name__ + "."):
        _obj.__module__ = __name__
del _name, _obj
