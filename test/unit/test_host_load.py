"""test/host_load.py: real-time shortfalls fail, unless the hypervisor starved the VM."""

import pytest

from host_load import STEAL_LIMIT, check_real_time, steal_fraction


def test_no_shortfall_passes_whatever_the_steal() -> None:
    check_real_time([], 0.9)


def test_shortfall_fails_with_its_figures_on_a_2_core_machine() -> None:
    with pytest.raises(pytest.fail.Exception, match=r'rtf \[0\.9\]; 3 lost \(hypervisor steal 5\.0%\)'):
        check_real_time(['rtf [0.9]', '3 lost'], 0.05)


def test_shortfall_under_steal_is_an_expected_failure() -> None:
    with pytest.raises(pytest.xfail.Exception, match='3 lost with 40% of the CPU'):
        check_real_time(['3 lost'], 0.40)
    with pytest.raises(pytest.fail.Exception):
        check_real_time(['3 lost'], STEAL_LIMIT)


def test_steal_fraction_is_steal_over_all_cpu_time() -> None:
    # user nice system idle iowait irq softirq steal guest guest_nice
    before = [100, 0, 50, 800, 0, 0, 0, 50, 0, 0]
    after = [200, 0, 100, 1000, 0, 0, 0, 150, 0, 0]
    assert steal_fraction(before, after) == pytest.approx(100 / 450)
