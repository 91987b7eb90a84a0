"""What `rps correlate` and `rps identify` share: the campaign option, the model's settings
(the scene's or the run's choice), and every check before the first solve."""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

from common.locations import DISTRIBUTION
from runtime.places import path_argument

from .args import cache_dir, cache_option, run_choice, with_choice, zone_cache


def campaign_options(p: argparse.ArgumentParser) -> None:
    p.add_argument("--campaign", metavar="TOML", type=path_argument, required=True,
                   help="test campaign file: the scene, the poses and their UFF files, "
                   "[identify] keys (docs/campaigns.md; required, no default)")
    p.add_argument("--from-results", metavar="JSON", type=path_argument,
                   help="use the model the validated run chose for the campaign's scene, read "
                   "from its results.json (default: the scene's own settings)")
    cache_option(p)
    p.add_argument("--json", action="store_true", help="print one JSON object, exact values")


def model_source(args: argparse.Namespace, campaign, chosen) -> tuple[object, str]:
    opts, source = with_choice(campaign.analytical, chosen, args)
    return opts, source or ("the campaign's [analytical]" if campaign.analytical_given else
                            "the scene's [analytical]" if campaign.scene.analytical_given else
                            "the scene's default settings")


def prepared(args: argparse.Namespace, fem: bool, need_keys: bool = False):
    """(campaign, model options, where they come from, FEM cache or None): the campaign read
    and checked whole, the output directory, --from-results and the cache checked, before any
    solve (and before the test files are read: a wrong option is said at once)."""
    from modaltest.campaign import load_campaign
    from runtime.outdir import check_output_dir

    chosen: dict = {}

    def before_data(scene) -> None:
        check_output_dir(args.out, "--out")
        args.scene = scene.path  # --from-results is checked against the campaign's scene
        chosen["run"] = run_choice(args, scene)
        if fem:
            cache_dir(args)

    campaign = load_campaign(args.campaign, need_keys=need_keys, before_data=before_data)
    options, source = model_source(args, campaign, chosen["run"])
    options = zone_cache(args, options)
    cache = None
    if fem:
        from runtime.cache import ResultCache
        cache = ResultCache(cache_dir(args))
    return campaign, options, source, cache


def page(kind: str, data, directory: Path) -> None:
    """DIR/<kind>.html from the record (the report room's page; without the report extra the
    JSON and CSVs stand alone, and the command says so on stderr)."""
    try:
        from reports import campaign_pages
    except ImportError as exc:
        print(f"note: {kind}.html not written: {exc.name} is missing (pip install "
              f"'{DISTRIBUTION}[report]')", file=sys.stderr)
        return
    html = getattr(campaign_pages, f"{kind}_page")(data)
    campaign_pages.write_page(html, directory / f"{kind}.html")
