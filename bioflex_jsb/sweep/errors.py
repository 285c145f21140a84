"""The campaign's input error: a leaf module that the campaign reader and its axes share."""

from __future__ import annotations

from bioflex_jsb.errors import InputError


class CampaignError(InputError):
    """A campaign file that cannot be used; the one-line message names the key."""
