#!/usr/bin/env python3
# Independent reference of the oblique impact (core/collision/oblique_impact.hpp), written from
# the physics rather than from the C++: the slip after impact is evaluated from both bodies'
# velocities (ball centre and spin; the bat's axis and roll) and solved for J_t (it is linear in
# J_t). Pins the numbers of tests/core/oblique_impact_test.cpp and prints the tables of
# docs/validation.md ("Oblique impact"):  python3 scripts/oblique_reference.py
import math
def add(a,b): return (a[0]+b[0], a[1]+b[1])
def mul(s,a): return (s*a[0], s*a[1])
def dot(a,b): return a[0]*b[0]+a[1]*b[1]
def solve(u=40.2336, delta=6.0, s_in_rpm=0.0, V=31.2928, A=10.0, D=0.0, r=0.0334, m=0.145,
          R=0.0366, alpha=0.4, Iroll=4.0e-4, Mn=float('inf'), e=0.5, ex=0.4, mu=0.5):
    d=math.radians(delta); a=math.radians(A)
    vb=(-u*math.cos(d), -u*math.sin(d)); vB=(V*math.cos(a), V*math.sin(a))
    om=-s_in_rpm*2*math.pi/60
    w=add(vb,mul(-1,vB)); nw=math.hypot(*w); ehat=mul(-1/nw,w); p=(-ehat[1], ehat[0])
    psi=math.asin(D/(R+r)); n=add(mul(math.cos(psi),ehat),mul(math.sin(psi),p)); t=(-n[1], n[0])
    I=alpha*m*R*R
    invMn = 0.0 if math.isinf(Mn) else 1/Mn
    invIr = 0.0 if math.isinf(Iroll) else 1/Iroll
    vn=-dot(w,n)
    Jn=(1+e)*vn/(1/m+invMn)
    def after(Jt):
        P=add(mul(Jn,n),mul(Jt,t))
        vba=add(vb,mul(1/m,P)); oma=om-R*Jt/I
        vBa=add(vB,mul(-invMn,P)); rolla=-r*Jt*invIr
        return vba,oma,vBa,rolla
    def slip(Jt):
        vba,oma,vBa,rolla=after(Jt)
        return (dot(vba,t)-R*oma) - (dot(vBa,t)+r*rolla)
    s0=slip(0.0); k=slip(1.0)-s0
    Jgrip=-(1+ex)*s0/k
    if abs(Jgrip)<=mu*Jn: Jt=Jgrip; reg='gripped'
    else: Jt=-math.copysign(mu*Jn, s0); reg='limited'
    vba,oma,vBa,rolla=after(Jt)
    return dict(speed=math.hypot(*vba), la=math.degrees(math.atan2(vba[1],vba[0])),
                rpm=oma*60/(2*math.pi), Jn=Jn, Jt=Jt, reg=reg)
def table():
    print("Issue case: 90 mph pitch 6 deg down, 2200 rpm backspin; 70 mph bat 10 deg up; M_n 0.5 kg, e 0.5, I_roll 4e-4 kg m^2")
    print("| undercut (in) | e_x | exit speed (mph) | launch (deg) | backspin (rpm) | Statcast relation -763 + 120 LA (rpm) |")
    print("|---|---|---|---|---|---|")
    for ex in [0.4, 0.2, 0.0]:
        for D_in in [0.25, 0.5, 0.75, 1.0]:
            r = solve(D=D_in*0.0254, Mn=0.5, s_in_rpm=2200, ex=ex)
            print("| %.2f | %.1f | %.1f | %.1f | %.0f | %.0f |" % (D_in, ex, r['speed']/0.44704, r['la'], r['rpm'], -763+120*r['la']))
    print()
    print("Fixed 3-in cylinder (Nathan et al. 2012 geometry), 120 mph, horizontal")
    print("| undercut (in) | psi (deg) | spin, e_x 0.4, any incident spin (rpm) | rolling, no incident spin (rpm) | rolling, 2000 rpm incident backspin (rpm) |")
    print("|---|---|---|---|---|")
    for D_in in [0.5, 1.0, 1.5, 2.0]:
        kw = dict(u=120*0.44704, delta=0, V=0, A=0, D=D_in*0.0254, r=1.5*0.0254, Mn=float('inf'), Iroll=float('inf'), mu=float('inf'))
        a = solve(ex=0.4, s_in_rpm=0, **kw); b = solve(ex=0.0, s_in_rpm=0, **kw); c = solve(ex=0.0, s_in_rpm=2000, **kw)
        psi = math.degrees(math.asin(D_in*0.0254/(0.0366+1.5*0.0254)))
        print("| %.1f | %.1f | %.0f | %.0f | %.0f |" % (D_in, psi, a['rpm'], b['rpm'], c['rpm']))

def pins():
    print("pins (tests/core/oblique_impact_test.cpp):")
    for D_in in [0.0, 0.25, 0.5, 0.75, 1.0, 1.5]:
        r = solve(D=D_in*0.0254, Mn=0.5, s_in_rpm=2200)
        print("  {%s, %.6f, %.6f, %.6f}," % (D_in, r['speed'], r['la'], r['rpm']))
    for ex in [0.4, 0.0]:
        f = solve(D=0.75*0.0254, Mn=0.5, s_in_rpm=2200, ex=ex)['rpm']
        c = solve(D=0.75*0.0254, Mn=0.5, s_in_rpm=-1500, ex=ex)['rpm']
        print("  curveball - fastball, e_x %.1f: %.6f rpm" % (ex, c - f))

if __name__=='__main__':
    table()
    print()
    pins()
