def test_demo_exits_zero(run_cli):
    rc, out, err = run_cli("demo", "--out", "unused")
    assert rc == 0 and "B6M" in out


def test_unknown_option_exit_2(run_cli, capsys):
    import pytest

    with pytest.raises(SystemExit) as e:
        run_cli("simulate", "--no-such-flag")
    assert e.value.code == 2
