"""epichead.replay: the CAN-log replay analysis on the real logs of ../shared/data/can."""
import json
import subprocess

import pytest

import epichead


def test_report_is_python_dicts_and_lists(can_dir):
    log = can_dir / "fesb_vcan0.log"
    r = epichead.replay(str(log))
    assert isinstance(r, dict)
    assert r["log"] == str(log)
    assert r["frames"] == len(log.read_text().split()) // 3 and r["malformed_lines"] == 0
    assert isinstance(r["ids"], list) and len(r["ids"]) > 0 and isinstance(r["ids"][0], dict)
    assert r["bitrate"] == 1_000_000 and r["duration_s"] > 0
    assert isinstance(r["fusion"], dict) and isinstance(r["head_controller"], dict)


def test_dbc_signals_decoded_as_the_command_does(can_dir, program):
    log, dbc = can_dir / "canbus_visualizer_can0.log", can_dir / "canbus_visualizer_anzen.dbc"
    r = epichead.replay(str(log), dbc=[str(dbc)])
    assert r["dbc"]["decoded_frames"] > 0
    assert len(r["dbc"]["messages"]) > 0
    out = subprocess.run([program, "replay", str(log), "--dbc", str(dbc), "--json"], check=True, capture_output=True,
                         text=True).stdout
    assert json.loads(out) == r


def test_text_report_is_the_commands(can_dir, program):
    log = can_dir / "rocketcan_canfd_vcan1.log"
    text = epichead.replay(str(log), text=True)
    out = subprocess.run([program, "replay", str(log)], check=True, capture_output=True, text=True).stdout
    assert text == out


def test_plots_and_signal_csv_are_written(can_dir, tmp_path):
    log, dbc = can_dir / "canbus_visualizer_can0.log", can_dir / "canbus_visualizer_anzen.dbc"
    epichead.replay(str(log), dbc=[str(dbc)], csv=str(tmp_path / "signals.csv"), plot_dir=str(tmp_path / "plots"))
    assert (tmp_path / "signals.csv").read_text().startswith("t_s,id,message,signal,raw,value,unit,text")
    assert (tmp_path / "plots" / "rates.png").stat().st_size > 0


def test_bitrate_changes_the_bus_load(can_dir):
    log = str(can_dir / "canbus_visualizer_can0.log")
    fast, slow = epichead.replay(log), epichead.replay(log, bitrate=500_000)
    assert slow["bus_load"] == pytest.approx(2 * fast["bus_load"], rel=1e-6)
