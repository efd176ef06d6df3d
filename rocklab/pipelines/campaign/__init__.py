"""Many experiments: a campaign run in parallel with its fits (η_mat, k, the Eq. 19 regression), and the demo."""

from ._campaign import CampaignResult, find_experiments, run_campaign
from ._demo import make_demo_campaign, run_demo
from ._groups import GROUPED_QUANTITIES, group_repeats

__all__ = [
    "run_campaign",
    "find_experiments",
    "CampaignResult",
    "group_repeats",
    "GROUPED_QUANTITIES",
    "run_demo",
    "make_demo_campaign",
]
