"""Private parameters of the monitor that it does not read are named, with a suggestion."""
from rubass.ros.params import KNOWN, unknown_params


def test_a_typo_gets_a_did_you_mean_and_known_or_foreign_names_are_quiet():
    names = ["/rubass/rat", "/rubass/spec", "/rubass/overload_action", "/rubass/extra/deep", "/rubassx/rat",
             "/use_sim_time", "/other/rat"] + [f"/rubass/{k}" for k in KNOWN]
    assert unknown_params(names, "/rubass") == [  # /rubass/extra/deep: a group, another node's (below)
        "unknown parameter ~overload_action (ignored); did you mean '~overload_actions'?",
        "unknown parameter ~rat (ignored); did you mean '~rate'?",
    ]


def test_a_namespaced_node_reads_its_own_names():
    assert unknown_params(["/robot1/safety/sepc", "/robot1/safety/spec"], "/robot1/safety") == [
        "unknown parameter ~sepc (ignored); did you mean '~spec'?"]


def test_another_nodes_parameters_in_the_monitors_namespace_are_not_typos():
    """Review finding: an agent launched in ns="rubass" has /rubass/rubass_agent_x/node_rate."""
    names = ["/rubass/spec", "/rubass/rubass_agent_x/node_rate", "/rubass/rubass_agent_x/discover_rate"]
    assert unknown_params(names, "/rubass") == []


def test_a_master_lost_while_the_parameters_are_read_is_a_sentence_not_a_traceback(monkeypatch):
    """A master that went away after init_node, before the parameters were read, gave rospy's
    ConnectionRefusedError traceback; the monitor and the agent now say `cannot start:` and why."""
    import pytest
    import rospy

    from rubass.ros.startup import MasterLost, private_param

    def refused(name, default=None):
        raise ConnectionRefusedError(111, "Connection refused")

    monkeypatch.setattr(rospy, "get_param", refused)
    monkeypatch.setenv("ROS_MASTER_URI", "http://localhost:11999")
    with pytest.raises(MasterLost) as err:
        private_param("spec", None)
    assert str(err.value) == ("the ROS master at http://localhost:11999 stopped answering while the parameters "
                              "were read (~spec: Connection refused)")
    monkeypatch.setattr(rospy, "get_param", lambda name, default=None: {"~rate": 20.0}.get(name, default))
    assert private_param("rate", 50.0) == 20.0 and private_param("spec", None) is None
