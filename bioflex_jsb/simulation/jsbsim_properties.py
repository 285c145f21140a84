"""JSBSim's property names as the package uses them: one place, so that every module reads
and writes the same names (a misspelt literal would make JSBSim create a new, unused
property). Each name carries its JSBSim unit (fps: ft/s, rad_sec: rad/s, lbs: lbf, psf:
lbf/ft², slugs_ft3: slug/ft³); the runtime converts at its boundary (bioflex_jsb.units).
Names of an engine or an axis are built by the functions at the end."""

from __future__ import annotations

# accelerations/
ACCELERATIONS_NZ = "accelerations/Nz"
ACCELERATIONS_PDOT_RAD_SEC2 = "accelerations/pdot-rad_sec2"
ACCELERATIONS_QDOT_RAD_SEC2 = "accelerations/qdot-rad_sec2"
ACCELERATIONS_RDOT_RAD_SEC2 = "accelerations/rdot-rad_sec2"
ACCELERATIONS_UDOT_FT_SEC2 = "accelerations/udot-ft_sec2"
ACCELERATIONS_VDOT_FT_SEC2 = "accelerations/vdot-ft_sec2"
ACCELERATIONS_WDOT_FT_SEC2 = "accelerations/wdot-ft_sec2"

# aero/
AERO_ALPHA_DEG = "aero/alpha-deg"
AERO_ALPHA_RAD = "aero/alpha-rad"
AERO_FORCE_MODAL_DRAG = "aero/force/modal-drag"
AERO_FORCE_MODAL_LIFT = "aero/force/modal-lift"
AERO_MOMENT_MODAL_PITCH = "aero/moment/modal-pitch"
AERO_QBAR_PSF = "aero/qbar-psf"
AERO_BI2VEL = "aero/bi2vel"  # b/(2V) [s]

# atmosphere/
ATMOSPHERE_RHO_SLUGS_FT3 = "atmosphere/rho-slugs_ft3"
ATMOSPHERE_WIND_DOWN_FPS = "atmosphere/wind-down-fps"
ATMOSPHERE_WIND_EAST_FPS = "atmosphere/wind-east-fps"
ATMOSPHERE_WIND_NORTH_FPS = "atmosphere/wind-north-fps"

# attitude/
ATTITUDE_PHI_RAD = "attitude/phi-rad"
ATTITUDE_PSI_RAD = "attitude/psi-rad"
ATTITUDE_THETA_RAD = "attitude/theta-rad"

# fcs/
FCS_AILERON_CMD_NORM = "fcs/aileron-cmd-norm"
FCS_AILERON_POS_NORM = "fcs/aileron-pos-norm"
FCS_AILERON_POS_RAD = "fcs/aileron-pos-rad"
FCS_ELEVATOR_CMD_NORM = "fcs/elevator-cmd-norm"
FCS_ELEVATOR_POS_NORM = "fcs/elevator-pos-norm"
FCS_ELEVATOR_POS_RAD = "fcs/elevator-pos-rad"
FCS_LEFT_AILERON_POS_NORM = "fcs/left-aileron-pos-norm"
FCS_LEFT_AILERON_POS_RAD = "fcs/left-aileron-pos-rad"
FCS_MIXTURE_CMD_NORM = "fcs/mixture-cmd-norm"
FCS_PITCH_TRIM_CMD_NORM = "fcs/pitch-trim-cmd-norm"
FCS_RIGHT_AILERON_POS_RAD = "fcs/right-aileron-pos-rad"
FCS_ROLL_TRIM_CMD_NORM = "fcs/roll-trim-cmd-norm"
FCS_RUDDER_CMD_NORM = "fcs/rudder-cmd-norm"
FCS_RUDDER_POS_RAD = "fcs/rudder-pos-rad"
FCS_THROTTLE_CMD_NORM_0 = "fcs/throttle-cmd-norm[0]"
FCS_THROTTLE_POS_NORM = "fcs/throttle-pos-norm"
FCS_YAW_TRIM_CMD_NORM = "fcs/yaw-trim-cmd-norm"

# flight-path/
FLIGHT_PATH_GAMMA_RAD = "flight-path/gamma-rad"

# forces/
FORCES_FBX_PROP_LBS = "forces/fbx-prop-lbs"
FORCES_FBX_TOTAL_LBS = "forces/fbx-total-lbs"
FORCES_FBY_TOTAL_LBS = "forces/fby-total-lbs"
FORCES_FBZ_TOTAL_LBS = "forces/fbz-total-lbs"
FORCES_FBY_AERO_LBS = "forces/fby-aero-lbs"
FORCES_FBZ_PROP_LBS = "forces/fbz-prop-lbs"
FORCES_FWX_AERO_LBS = "forces/fwx-aero-lbs"
FORCES_FWZ_AERO_LBS = "forces/fwz-aero-lbs"

# ic/
IC_ALPHA_RAD = "ic/alpha-rad"
IC_BETA_RAD = "ic/beta-rad"
IC_GAMMA_RAD = "ic/gamma-rad"
IC_H_SL_FT = "ic/h-sl-ft"
IC_LAT_GEOD_RAD = "ic/lat-geod-rad"
IC_LONG_GC_RAD = "ic/long-gc-rad"
IC_P_RAD_SEC = "ic/p-rad_sec"
IC_PHI_RAD = "ic/phi-rad"
IC_PSI_TRUE_RAD = "ic/psi-true-rad"
IC_Q_RAD_SEC = "ic/q-rad_sec"
IC_R_RAD_SEC = "ic/r-rad_sec"
IC_TERRAIN_ELEVATION_FT = "ic/terrain-elevation-ft"
IC_THETA_RAD = "ic/theta-rad"
IC_U_FPS = "ic/u-fps"
IC_V_FPS = "ic/v-fps"
IC_VT_FPS = "ic/vt-fps"
IC_W_FPS = "ic/w-fps"

# inertia/
INERTIA_MASS_SLUGS = "inertia/mass-slugs"
INERTIA_IXX_SLUGS_FT2 = "inertia/ixx-slugs_ft2"

# metrics/
METRICS_SW_SQFT = "metrics/Sw-sqft"
METRICS_BW_FT = "metrics/bw-ft"
METRICS_CBARW_FT = "metrics/cbarw-ft"

# moments/
MOMENTS_L_AERO_LBSFT = "moments/l-aero-lbsft"
MOMENTS_M_AERO_LBSFT = "moments/m-aero-lbsft"
MOMENTS_M_PROP_LBSFT = "moments/m-prop-lbsft"
MOMENTS_N_AERO_LBSFT = "moments/n-aero-lbsft"

# position/
POSITION_H_AGL_FT = "position/h-agl-ft"
POSITION_H_SL_FT = "position/h-sl-ft"
POSITION_LAT_GEOD_RAD = "position/lat-geod-rad"
POSITION_LONG_GC_RAD = "position/long-gc-rad"
POSITION_TERRAIN_ELEVATION_ASL_FT = "position/terrain-elevation-asl-ft"

# propulsion/
PROPULSION_ENGINE_0_PROPELLER_RPM = "propulsion/engine[0]/propeller-rpm"
PROPULSION_SET_RUNNING = "propulsion/set-running"

# velocities/
VELOCITIES_P_RAD_SEC = "velocities/p-rad_sec"
VELOCITIES_Q_RAD_SEC = "velocities/q-rad_sec"
VELOCITIES_R_RAD_SEC = "velocities/r-rad_sec"
VELOCITIES_U_FPS = "velocities/u-fps"
VELOCITIES_V_DOWN_FPS = "velocities/v-down-fps"
VELOCITIES_V_EAST_FPS = "velocities/v-east-fps"
VELOCITIES_V_FPS = "velocities/v-fps"
VELOCITIES_V_NORTH_FPS = "velocities/v-north-fps"
VELOCITIES_W_FPS = "velocities/w-fps"
VELOCITIES_VT_FPS = "velocities/vt-fps"

# simulation/: JSBSim's integrator choices (FGPropagate)
INTEGRATOR_PROPERTIES = tuple(f"simulation/integrator/{a}/{b}" for a in ("rate", "position")
                              for b in ("rotational", "translational"))


def engine(index: int, leaf: str) -> str:
    """``propulsion/engine[index]/leaf`` (``thrust-lbs``, ``propeller-rpm``, ...)."""
    return f"propulsion/engine[{index}]/{leaf}"


def throttle_cmd(index: int) -> str:
    """The throttle command of engine ``index`` [0..1]."""
    return f"fcs/throttle-cmd-norm[{index}]"


def inertia_slugs_ft2(moment: str) -> str:
    """``inertia/<moment>-slugs_ft2``: ``ixx``, ``iyy``, ``izz``, ``ixz`` [slug·ft²]."""
    return f"inertia/{moment}-slugs_ft2"


def cg_in(axis: str) -> str:
    """The CG's structural-frame coordinate ``axis`` (x, y, z) [in]."""
    return f"inertia/cg-{axis}-in"


def aero_rp_in(axis: str) -> str:
    """The aerodynamic reference point's structural-frame coordinate ``axis`` [in]."""
    return f"metrics/aero-rp-{axis}-in"


def external_force_magnitude(name: str) -> str:
    """The magnitude [lbf] of the external force ``name`` (``modal-lift``, ...)."""
    return f"external_reactions/{name}/magnitude"
