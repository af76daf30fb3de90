"""reproduction.py: the control run is the same campaign without the installation sensitivity."""

from __future__ import annotations


def test_the_control_campaign_differs_only_in_the_installation_sensitivity() -> None:
    import dataclasses

    from clearjoint.reproduction import without_installation_sensitivity
    from clearjoint.rig import load_campaign

    campaign = load_campaign()
    control = without_installation_sensitivity(campaign)
    assert campaign.rig.frequency_sensitivity > 0
    assert campaign.rig.amplitude_sensitivity > 0
    assert control.rig.frequency_sensitivity == 0.0
    assert control.rig.amplitude_sensitivity == 0.0
    changed = {
        f.name
        for f in dataclasses.fields(campaign.rig)
        if getattr(campaign.rig, f.name) != getattr(control.rig, f.name)
    }
    assert changed == {"frequency_sensitivity", "amplitude_sensitivity"}
    assert control.tests == campaign.tests
    assert control.seed == campaign.seed
