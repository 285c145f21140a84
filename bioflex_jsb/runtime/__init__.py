"""The JSBSim runtime: the one package that imports :mod:`jsbsim`.

Everything crossing its boundary is SI (m, s, kg, N, rad); JSBSim's slug-ft-s and degree
values are converted here, once. ``fdm``: loading the airframe, trim, properties and steps;
``linearization``: JSBSim's linear model reduced to the paper's rigid states;
``coupled_step``: the one co-simulation step that every driver runs.
"""
