"""Unit conversions used at the JSBSim boundary (JSBSim works in slug-ft-s and degrees).

Inside bioflex-jsb everything is SI; convert once, where a value crosses into or out of
JSBSim, with these named constants.
"""

FT_PER_M = 1.0 / 0.3048
M_PER_FT = 0.3048
LBF_PER_N = 1.0 / 4.4482216152605
N_PER_LBF = 4.4482216152605
SLUG_PER_KG = 1.0 / 14.593902937206364
KG_PER_SLUG = 14.593902937206364
SLUG_FT2_PER_KG_M2 = SLUG_PER_KG * FT_PER_M**2
FT2_PER_M2 = FT_PER_M**2
LBF_FT_PER_N_M = LBF_PER_N * FT_PER_M
N_M_PER_LBF_FT = N_PER_LBF * M_PER_FT
PSF_PER_PA = LBF_PER_N / FT2_PER_M2
PA_PER_PSF = 1.0 / PSF_PER_PA
SLUG_FT3_PER_KG_M3 = SLUG_PER_KG / FT_PER_M**3
KG_M3_PER_SLUG_FT3 = 1.0 / SLUG_FT3_PER_KG_M3
KTS_PER_M_S = 3600.0 / 1852.0
M_S_PER_KTS = 1852.0 / 3600.0
WATT_PER_HP = 745.69987158227022
