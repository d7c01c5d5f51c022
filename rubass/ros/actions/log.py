"""The `log` plugin: a line in the node's log (and /rosout) per behaviour start and release."""
from __future__ import annotations

import rospy

from ...actions.base import ActionPlugin, Context, describe
from ...lang.fmt import format_number


class LogPlugin(ActionPlugin):
    per_behaviour = True

    def _text(self, ctx: Context, what: str) -> str:
        given = " ".join(format_number(a) if type(a) is float else str(a) for a in ctx.args) \
            or self.params.get("message") or ""  # warn("left", 3, "zone"): "left 3 zone", not 3.0
        return f"{given + ': ' if given else ''}{describe(ctx)} {what}"

    def start(self, ctx: Context) -> None:
        level = self.params.get("level", "warn")
        log = {"debug": rospy.logdebug, "info": rospy.loginfo, "warn": rospy.logwarn, "error": rospy.logerr}[level]
        log("rubass: %s", self._text(ctx, "started"))

    def release(self, ctx: Context) -> None:
        rospy.loginfo("rubass: %s", self._text(ctx, "released"))
