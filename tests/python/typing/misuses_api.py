"""Wrong uses of the redres API that mypy must reject through the stub and the annotations (check_typing.py): each
line marked `# error` is one."""

import redres

robot = redres.Robot.load("robot.toml")
robot.dof + "1"  # error
robot.kinematics(robot.home).w.upper()  # error
redres.compare(["a.toml"], jobs="2")  # error
redres.Controller(robot, T="1")  # error
ctrl = redres.Controller(robot)
ctrl.step(robot.home)  # error
ctrl.qp["W"].no_such_attribute  # error
redres.Scenario.load("s.toml").run().final_theta.no_such_attribute  # error
