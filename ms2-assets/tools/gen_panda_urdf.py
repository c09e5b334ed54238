#!/usr/bin/env python3
"""Writes ms2-assets/robots/panda/panda.urdf from the Panda's published parameters.

Run from the repository root: python3 ms2-assets/tools/gen_panda_urdf.py (needs numpy).
"""
import numpy as np
from math import pi
def rpy(r,p,y):
    cr,sr,cp,sp,cy,sy=np.cos(r),np.sin(r),np.cos(p),np.sin(p),np.cos(y),np.sin(y)
    Rx=np.array([[1,0,0],[0,cr,-sr],[0,sr,cr]]);Ry=np.array([[cp,0,sp],[0,1,0],[-sp,0,cp]]);Rz=np.array([[cy,-sy,0],[sy,cy,0],[0,0,1]])
    return Rz@Ry@Rx
def T(xyz,r):
    M=np.eye(4);M[:3,:3]=rpy(*r);M[:3,3]=xyz;return M
joints=[ # name, parent, child, xyz, rpy, type, axis, lower, upper, effort, vel
("panda_joint1","panda_link0","panda_link1",(0,0,0.333),(0,0,0),"revolute",(0,0,1),-2.8973,2.8973,87,2.175),
("panda_joint2","panda_link1","panda_link2",(0,0,0),(-pi/2,0,0),"revolute",(0,0,1),-1.7628,1.7628,87,2.175),
("panda_joint3","panda_link2","panda_link3",(0,-0.316,0),(pi/2,0,0),"revolute",(0,0,1),-2.8973,2.8973,87,2.175),
("panda_joint4","panda_link3","panda_link4",(0.0825,0,0),(pi/2,0,0),"revolute",(0,0,1),-3.0718,-0.0698,87,2.175),
("panda_joint5","panda_link4","panda_link5",(-0.0825,0.384,0),(-pi/2,0,0),"revolute",(0,0,1),-2.8973,2.8973,12,2.61),
("panda_joint6","panda_link5","panda_link6",(0,0,0),(pi/2,0,0),"revolute",(0,0,1),-0.0175,3.7525,12,2.61),
("panda_joint7","panda_link6","panda_link7",(0.088,0,0),(pi/2,0,0),"revolute",(0,0,1),-2.8973,2.8973,12,2.61),
("panda_joint8","panda_link7","panda_link8",(0,0,0.107),(0,0,0),"fixed",None,0,0,0,0),
("panda_hand_joint","panda_link8","panda_hand",(0,0,0),(0,0,-pi/4),"fixed",None,0,0,0,0),
("panda_hand_tcp_joint","panda_hand","panda_hand_tcp",(0,0,0.1034),(0,0,0),"fixed",None,0,0,0,0),
("panda_finger_joint1","panda_hand","panda_leftfinger",(0,0,0.0584),(0,0,0),"prismatic",(0,1,0),0.0,0.04,20,0.2),
("panda_finger_joint2","panda_hand","panda_rightfinger",(0,0,0.0584),(0,0,0),"prismatic",(0,-1,0),0.0,0.04,20,0.2),
]
world={"panda_link0":np.eye(4)}
for j in joints: world[j[2]]=world[j[1]]@T(j[3],j[4])
for k,v in world.items(): print("#",k,np.round(v[:3,3],4))
inertial={
"panda_link0":(0.629769,(-0.041018,-0.00014,0.049974),(0.00315,8.2904e-7,0.00015,0.00388,8.2299e-6,0.004285)),
"panda_link1":(4.970684,(0.003875,0.002081,-0.04762),(0.70337,-0.000139,0.006772,0.70661,0.019169,0.009117)),
"panda_link2":(0.646926,(-0.003141,-0.02872,0.003495),(0.007962,-0.003925,0.010254,0.02811,0.000704,0.025995)),
"panda_link3":(3.228604,(0.027518,0.039252,-0.066502),(0.037242,-0.004761,-0.011396,0.036155,-0.012805,0.01083)),
"panda_link4":(3.587895,(-0.05317,0.104419,0.027454),(0.025853,0.007796,-0.001332,0.019552,0.008641,0.028323)),
"panda_link5":(1.225946,(-0.011953,0.041065,-0.038437),(0.035549,-0.002117,-0.004037,0.029474,0.000229,0.008627)),
"panda_link6":(1.666555,(0.060149,-0.014117,-0.010517),(0.001964,0.000109,-0.001158,0.004354,0.000341,0.005433)),
"panda_link7":(0.735522,(0.010517,-0.004252,0.061597),(0.012516,-0.000428,-0.001196,0.010027,-0.000741,0.004815)),
"panda_hand":(0.73,(-0.01,0,0.03),(0.001,0,0,0.0025,0,0.0017)),
"panda_leftfinger":(0.015,(0,0.0145,0.027),(2.375e-6,0,0,2.375e-6,0,7.5e-7)),
"panda_rightfinger":(0.015,(0,-0.0145,0.027),(2.375e-6,0,0,2.375e-6,0,7.5e-7)),
}
# Collision/visual cylinders as world-frame segments at q = 0 (arm upright, hand pointing down).
segs={
"panda_link0":[((0,0,0.0),(0,0,0.14),0.075), ((-0.09,0,0.05),(0.0,0,0.05),0.055)],
"panda_link1":[((0,0,0.17),(0,0,0.30),0.06), ((0,-0.07,0.333),(0,0.07,0.333),0.06)],
"panda_link2":[((0,0,0.38),(0,0,0.50),0.06)],
"panda_link3":[((0,0,0.52),(0,0,0.62),0.06), ((0.0825,-0.065,0.649),(0.0825,0.065,0.649),0.055)],
"panda_link4":[((0.07,0,0.68),(0.02,0,0.80),0.055)],
"panda_link5":[((0,0,0.84),(0,0,0.98),0.05), ((0,-0.06,1.033),(0,0.06,1.033),0.05)],
"panda_link6":[((0.0,0,1.033),(0.088,0,1.033),0.05)],
"panda_link7":[((0.088,0,0.95),(0.088,0,1.06),0.045)],
}
def cyl_in_link(link,a,b,r):
    M=np.linalg.inv(world[link]); a=M@np.array([*a,1]); b=M@np.array([*b,1]); a=a[:3]; b=b[:3]
    c=(a+b)/2; d=b-a; L=np.linalg.norm(d); z=d/L
    # rpy rotating local z onto z: R = Rz(yaw) Ry(pitch)
    pitch=np.arccos(np.clip(z[2],-1,1)); yaw=np.arctan2(z[1],z[0])
    R=rpy(0,pitch,yaw); assert np.allclose(R[:,2],z,atol=1e-9)
    return c,(0,pitch,yaw),L,r
def f(x): return " ".join(f"{v:.6g}" if abs(v)>1e-12 else "0" for v in x)
out=['<?xml version="1.0"?>','<!-- Franka Emika Panda with two-finger hand, written for ms2 from the robot\'s published',
'     kinematic and inertial parameters. Geometry is built from primitives (no mesh files). -->',
'<robot name="panda">',
'  <material name="panda_white"><color rgba="0.95 0.95 0.95 1"/></material>',
'  <material name="panda_dark"><color rgba="0.25 0.25 0.27 1"/></material>']
def geom(tag,origin,shape,mat=None):
    s=f'    <{tag}>\n      <origin xyz="{f(origin[0])}" rpy="{f(origin[1])}"/>\n      <geometry>{shape}</geometry>\n'
    if mat: s+=f'      <material name="{mat}"/>\n'
    return s+f'    </{tag}>'
links=["panda_link0"]+[j[2] for j in joints]
for L in links:
    out.append(f'  <link name="{L}">')
    if L in inertial:
        m,c,I=inertial[L]
        out.append(f'    <inertial>\n      <origin xyz="{f(c)}" rpy="0 0 0"/>\n      <mass value="{m}"/>\n      <inertia ixx="{I[0]}" ixy="{I[1]}" ixz="{I[2]}" iyy="{I[3]}" iyz="{I[4]}" izz="{I[5]}"/>\n    </inertial>')
    shapes=[]
    for a,b,r in segs.get(L,[]):
        c,rp,Ln,r=cyl_in_link(L,a,b,r)
        # Visual: the cylinder. Collision: a capsule within the same extent (cylinder part
        # shortened by the two caps), which collides faster and more smoothly than a cylinder.
        col=f'<capsule radius="{r}" length="{max(Ln-2*r,1e-3):.5g}"/>'
        shapes.append(((c,rp),f'<cylinder radius="{r}" length="{Ln:.5g}"/>', "panda_dark" if L in ("panda_link7",) else "panda_white", col))
    if L=="panda_hand":
        shapes.append((((0,0,0.03),(0,0,0)),'<box size="0.06 0.2 0.06"/>',"panda_white",None))
    if L in ("panda_leftfinger","panda_rightfinger"):
        s=1 if L=="panda_leftfinger" else -1
        # Upper finger body; its inner face is set back 4 mm from the pad so objects meet the pad.
        shapes.append((((0,s*0.012,0.017),(0,0,0)),'<box size="0.02 0.016 0.034"/>',"panda_dark",None))
        # Fingertip pad: inner face at y = 0 in the finger frame (fingers touch at q = 0).
        shapes.append((((0,s*0.006,0.044),(0,0,0)),'<box size="0.02 0.012 0.02"/>',"panda_dark",None))
    for o,sh,mat,col in shapes:
        out.append(geom("visual",o,sh,mat)); out.append(geom("collision",o,col or sh))
    out.append('  </link>')
for j in joints:
    n,p,c,xyz,r,t,ax,lo,up,eff,vel=j
    s=f'  <joint name="{n}" type="{t}">\n    <parent link="{p}"/>\n    <child link="{c}"/>\n    <origin xyz="{f(xyz)}" rpy="{f(r)}"/>'
    if ax:
        s+=f'\n    <axis xyz="{f(ax)}"/>\n    <limit lower="{lo}" upper="{up}" effort="{eff}" velocity="{vel}"/>'
    if n=="panda_finger_joint2": s+='\n    <mimic joint="panda_finger_joint1" multiplier="1" offset="0"/>'
    out.append(s+'\n  </joint>')
out.append('</robot>')
open("ms2-assets/robots/panda/panda.urdf","w").write("\n".join(out)+"\n")
