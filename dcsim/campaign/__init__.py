"""Campaigns: many cases of one scenario (Monte Carlo draws and grid sweeps) run on Dask.

:func:`run_campaign` runs a campaign file's cases on a local cluster or an existing
one and returns their table; :func:`resume_campaign` completes an interrupted one and
:func:`replay_case` repeats one case bit for bit. docs/campaigns.md describes the file
format, clusters, failures and replay.
"""

from dcsim.campaign.cases import Case, campaign_cases
from dcsim.campaign.engine import ClusterError, ClusterOptions
from dcsim.campaign.run import (
    CampaignDirectoryError,
    CampaignRun,
    Replay,
    replay_case,
    resume_campaign,
    run_campaign,
)
from dcsim.campaign.spec import Campaign, CampaignSpec, load_campaign

__all__ = [
    "Campaign",
    "CampaignDirectoryError",
    "CampaignRun",
    "CampaignSpec",
    "Case",
    "ClusterError",
    "ClusterOptions",
    "Replay",
    "campaign_cases",
    "load_campaign",
    "replay_case",
    "resume_campaign",
    "run_campaign",
]
