"""A winch drum reels a cable in through a 3D conduit, in your own Exudyn model.

The drum is an Exudyn rigid body on a revolute joint, turned by a servo motor (a rotational
spring-damper toward a reference angle that turns at the reeling speed). exucable adds the cable,
its pre-tensioned start in the conduit and the wall contact to the same system, reeled onto the
drum's angle; Exudyn's own ``mbs.SolveDynamic`` runs it with settings the script owns.

Once steady, the motor torque over the drum radius is the cable's pulling force; it is checked
against ``xc.run`` of the same scenario with exucable's built-in velocity rig.

Run: ``python examples/winch_drum.py`` (about a minute); the test suite runs ``main(end_time=...)``.
"""

import numpy as np
import exudyn as exu
from exudyn.utilities import InertiaCylinder

import exucable as xc
from exudyn.itemInterface import (CoordinateConstraint, CoordinateSpringDamper, MarkerNodeCoordinate,
                                  NodeGenericODE2, NodePointGround)


def scenario(end_time=1.0):
    """3D route: a left bend, then up and over a crest; 50 N back tension, gravity, μ 0.2."""
    route = (xc.Route(inner_radius=3.5e-3)
             .straight(1.0).bend(90, radius=0.5, turn="left").straight(0.5)
             .bend(30, radius=0.5, turn="up").straight(0.3).bend(30, radius=0.5, turn="down").straight(0.5))
    return xc.Scenario(route=route, cable=xc.Cable(radius=2.5e-3, density=1000.0, youngs_modulus=1e9),
                       contact=xc.Contact(friction=0.2), pull=xc.Pull(speed=0.1, back_tension=50.0),
                       gravity=xc.Gravity(g=9.81), solver=xc.Solver(end_time=end_time))


def main(end_time=1.0, drum_radius_m=0.2, steady_from_s=None):
    sc = scenario(end_time)
    speed = sc.pull.speed_m_per_s
    omega = speed / drum_radius_m                       # reeling rate [rad/s]

    SC = exu.SystemContainer()
    mbs = SC.AddSystem()

    # --- the user's drum: a rigid cylinder about z, turned by a servo motor
    start = xc.initial_layout(sc)
    centre = start.leading_position_m + [0.0, 0.0, drum_radius_m]
    ground = mbs.CreateGround()
    drum = mbs.CreateRigidBody(
        inertia=InertiaCylinder(density=2700.0, length=0.02, outerRadius=drum_radius_m, axis=2),
        referencePosition=centre, initialAngularVelocity=[0.0, 0.0, omega], nodeType=exu.NodeType.RotationRxyz)
    mbs.CreateRevoluteJoint(itemNumbers=[ground, drum], position=centre, axis=[0, 0, 1], useGlobalFrame=True)
    drum_node = mbs.GetObject(drum)["nodeNumber"]
    drum_angle = mbs.AddMarker(MarkerNodeCoordinate(nodeNumber=drum_node, coordinate=5))  # Rxyz: angle about z

    # servo: reference angle ω·t (a driven coordinate), spring-damper from it to the drum angle
    ref_node = mbs.AddNode(NodeGenericODE2(numberOfODE2Coordinates=1, referenceCoordinates=[0.0],
                                           initialCoordinates=[0.0], initialCoordinates_t=[omega]))
    ref_angle = mbs.AddMarker(MarkerNodeCoordinate(nodeNumber=ref_node, coordinate=0))
    fixed = mbs.AddMarker(MarkerNodeCoordinate(nodeNumber=mbs.AddNode(NodePointGround()), coordinate=0))
    mbs.AddObject(CoordinateConstraint(markerNumbers=[fixed, ref_angle],
                                       offsetUserFunction=lambda mbs, t, i, off: omega * t,
                                       offsetUserFunction_t=lambda mbs, t, i, off: omega))
    motor = mbs.AddObject(CoordinateSpringDamper(markerNumbers=[drum_angle, ref_angle],
                                                 stiffness=1.0e4, damping=60.0))   # [N m/rad], [N m s/rad]

    # --- exucable's cable, reeled onto the drum angle
    cable = xc.add_cable_in_conduit(mbs, sc, leading=xc.ReelOnto(drum_angle, drum_radius_m), start=start)

    torque = []

    def post_step(mbs, t):
        cable.recorder(mbs, t)
        if len(cable.recorder.history.time_s) > len(torque):
            torque.append(mbs.GetObjectOutput(motor, exu.OutputVariableType.Force))  # motor torque [N m]
        return True

    mbs.SetPostStepUserFunction(post_step)
    mbs.Assemble()
    settings = cable.recommended_settings()
    settings.timeIntegration.endTime = end_time
    mbs.SolveDynamic(settings)

    h = cable.recorder.history
    t = np.asarray(h.time_s)
    steady = t >= (end_time / 2 if steady_from_s is None else steady_from_s)
    drum_force = float(np.mean(np.asarray(torque)[steady])) / drum_radius_m
    reel_force = float(np.mean(np.asarray(h.pull_force_N)[steady]))
    rig = xc.run(sc)
    print(f"drum torque / radius  {drum_force:9.3f} N")
    print(f"cable tension at reel {reel_force:9.3f} N")
    print(f"exucable's rig        {rig.pull_force_N:9.3f} N ± {rig.pull_force_uncertainty_N:.2g}")
    print(f"difference            {100 * (drum_force / rig.pull_force_N - 1):+.3f} %")
    print(f"torque scatter        {np.std(np.asarray(torque)[steady]) / drum_radius_m:9.3f} N (std / radius)")
    return drum_force, rig.pull_force_N, cable


if __name__ == "__main__":
    main()
