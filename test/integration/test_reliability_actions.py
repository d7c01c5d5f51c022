"""Issue 20 (3): the same action twice in one behaviour runs twice in the live monitor."""
import pytest
from rosharness import spec, wait_log

pytestmark = [pytest.mark.ros, pytest.mark.slow]


def test_two_calls_of_one_action_in_one_behaviour_both_run_and_both_release(ros, tmp_path):
    mon = ros.monitor(spec(tmp_path, 'entity e { rules: a: topic /x.data > 1; }\n'
                                     'if (e.a) then { warn("alpha"); warn("beta"); }\n'))
    ros.probe({"advertise": [{"topic": "/x", "type": "std_msgs/Float64"}],
               "steps": [{"wait_subscribers": "/x"}, {"sleep": 0.3}, {"publish": "/x", "msg": {"data": 5.0}},
                         {"sleep": 0.3}, {"publish": "/x", "msg": {"data": 0.0}}, {"sleep": 0.3}]})
    for text in ("alpha: behaviour 1", "beta: behaviour 1"):
        wait_log(mon, ros, text + " (line 4) (e.a) started")
        wait_log(mon, ros, text + " (line 4) released")
