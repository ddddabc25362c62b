"""Image metrics the benchmarks report (relMSE, relative variance from a seed pair, means and their
standard errors...): numpy functions over (H, W, C) arrays, shared with the project's benchmark tools."""
from neepp_tools.metrics import *  # noqa: F401,F403
from neepp_tools.metrics import __all__  # noqa: F401
