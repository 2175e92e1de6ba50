#!/usr/bin/python3
"""LAMMPS decks of the brittle reference system (docs/fracture.md, 'A brittle reference system').

A 2D triangular lattice (LAMMPS `dimension 2`, lj units, close-packed rows along x) of one of the
pair models below. Writes into DIR:

  potential.mod  the pair model (pdcg reads it too: `pdcg atoms2pd --potential`)
  in.relax       zero-stress lattice (fix box/relax) -> a0.txt (nearest-neighbour distance)
  in.surface     edge energy gamma (energy per unit length) of the close-packed row, unrelaxed
                 and relaxed, by LAMMPS alone -> gamma.txt
  in.fracture    notched sheet pulled to rupture (see the header of the deck)
  in.griffith    the same sheet at T = 0 by molecular statics: stored energy at a small strain
                 (griffith.py: energy release rate G(a) and the Griffith load of the geometry)

Usage: make_decks.py --system NAME DIR
Systems (all 12-6 Lennard-Jones, eps = sigma = 1, or Morse):
  lj25    lj/cut 2.5, energy shifted (the flagship sheet's model)
  lj15    lj/cut 1.5, energy shifted: nearest neighbours only (second shell at sqrt(3) a0 = 1.94)
  ljsl15  lj/smooth/linear 1.5: force and energy continuous at the cutoff, nearest neighbours only
  morseA_RC  morse D0 = 1, alpha = A, r0 = 2^(1/6), cutoff RC (7_1.5, 7_1.8, 7_1.9, 6_1.8, 5_2.0,
             10_1.5), energy
             shifted: nearest neighbours only
"""
import argparse
import os

SYSTEMS = {
    "lj25": ("pair_style      lj/cut 2.5\npair_coeff      * * 1.0 1.0 2.5\n"
             "pair_modify     shift yes\n", "pair_coeff 2 3 0.0 1.0", 2.5),
    "lj15": ("pair_style      lj/cut 1.5\npair_coeff      * * 1.0 1.0 1.5\n"
             "pair_modify     shift yes\n", "pair_coeff 2 3 0.0 1.0", 1.5),
    "ljsl15": ("pair_style      lj/smooth/linear 1.5\npair_coeff      * * 1.0 1.0 1.5\n",
               "pair_coeff 2 3 0.0 1.0", 1.5),
}


def morse(alpha, rc):
    r0 = 1.122462048309373  # 2^(1/6): the LJ minimum, so the lattice is that of lj15
    return (f"pair_style      morse {rc}\npair_coeff      * * 1.0 {alpha} {r0} {rc}\n"
            "pair_modify     shift yes\n", f"pair_coeff 2 3 0.0 {alpha} {r0}", rc)


for _a, _rc in ((7, 1.5), (7, 1.8), (7, 1.9), (6, 1.8), (5, 2.0), (10, 1.5)):
    SYSTEMS[f"morse{_a}_{_rc}"] = morse(_a, _rc)

RELAX = """# Zero-stress 2D triangular lattice of potential.mod: a periodic 12 x 7 hex-cell cell relaxed
# with fix box/relax (P_xx = P_yy = 0); writes the nearest-neighbour distance to ${out}/a0.txt and
# the relaxed cell to ${out}/perfect.data.
# Run: lmp -in in.relax -var out <dir>
variable out index .
units           lj
dimension       2
atom_style      atomic
boundary        p p p
variable        a equal 1.12
lattice         hex $(2.0/(sqrt(3.0)*v_a*v_a))
region          box block 0 12 0 7 -0.5 0.5
create_box      3 box
create_atoms    1 box
mass            * 1.0
include         potential.mod
thermo_style    custom step pe pxx pyy lx ly
fix             relax all box/relax x 0.0 y 0.0 couple none vmax 0.001
min_style       cg
minimize        1.0e-15 1.0e-12 5000 50000
unfix           relax
minimize        1.0e-15 1.0e-12 5000 50000
variable        a0 equal lx/12
print           "$(v_a0:%.15g)" file ${out}/a0.txt screen no
print           "relaxed a0 = $(v_a0:%.15g), pe/atom = $(pe:%.15g), pxx = $(pxx), pyy = $(pyy)"
write_data      ${out}/perfect.data
"""

SURFACE = """# Edge energy gamma (energy per unit length) of the close-packed row of the 2D lattice, by
# LAMMPS alone: an nx x ny hex-cell periodic cell at the zero-stress a0, then y made non-periodic
# (two edges of length L_x), unrelaxed (run 0) and relaxed (minimize at fixed L_x).
#   gamma = (E_edge - E_bulk) / (2 L_x)
# Run: lmp -in in.surface -var out <dir>   (after in.relax)
variable out index .
variable nx index 8
variable ny index 10
units           lj
dimension       2
atom_style      atomic
boundary        p p p
variable        a0 file ${out}/a0.txt
lattice         hex $(2.0/(sqrt(3.0)*v_a0*v_a0))
region          box block 0 ${nx} 0 ${ny} -0.5 0.5
create_box      3 box
create_atoms    1 box
mass            * 1.0
include         potential.mod
thermo_style    custom step pe lx ly
thermo_modify   norm no
run             0
variable        Eb equal $(pe:%.17g)
variable        Lx equal $(lx:%.17g)
displace_atoms  all move 0.0 $(0.25*sqrt(3.0)/2.0*v_a0) 0.0 units box
change_box      all boundary p s p
run             0
variable        Eu equal $(pe:%.17g)
min_style       cg
minimize        0.0 1.0e-12 100000 1000000
variable        Er equal $(pe:%.17g)
print           "gamma_unrelaxed $(( v_Eu - v_Eb ) / (2.0*v_Lx):%.15g)" file ${out}/gamma.txt
print           "gamma_relaxed $(( v_Er - v_Eb ) / (2.0*v_Lx):%.15g)" append ${out}/gamma.txt
print           "E_bulk ${Eb} E_unrelaxed ${Eu} E_relaxed ${Er} Lx ${Lx} fnorm $(fnorm)" append ${out}/gamma.txt
"""

FRACTURE = """# Notched 2D triangular sheet pulled to rupture (docs/fracture.md, 'A brittle reference system').
#   Sheet: nx x ny hex cells, rows of nx atoms along x (width W = nx a0), 2 ny rows (row spacing
#   h = sqrt(3)/2 a0); free edges (boundary s s p). Crack plane: between rows ny-1 and ny
#   (y_c = (ny - 1/2) h).
#   Notch: an atomically sharp edge crack of length a = notch a0 from the left edge: the atoms
#   with x < a within r_cut of the crack plane get type 2 (above) and 3 (below), and the 2-3
#   interaction is zero (__CUT__). No atom is removed.
#   Grips: the two bottom rows are held in y, the two top rows move at v = rate L0 in y; both are
#   free to slide in x (frictionless grips: no corner singularity where a grip meets a free edge).
#   L0 = distance between the grip rows' centres; velocity ramp start; Langevin bath at T
#   (damping damp) on v_x of the free atoms.
#   Tip: coordination (compute coord/atom, cutoff rb) of every atom more than 2 sigma inside the
#   sheet; the crack tip is the largest x of an interior atom with fewer than 6 neighbours;
#   'defects' counts interior atoms with a coordination other than 6 farther than 3h from the
#   crack plane (dislocations, voids, branches).
#   Dumps every `sparse` steps, every `dense` steps once the tip has run 3 a0 past the notch; the
#   run stops `extra` steps after the tip is within 4 sigma of the right edge (or at strain_max).
#   Output: ${out}/series.txt (step strain stress tip defects temp), ${out}/meta.txt,
#   ${out}/frames.dump (id type x y c_coord, sorted by id).
# Run: lmp -in in.fracture -var out <dir> -var nx .. -var ny .. -var notch .. -var rate ..
variable out index .
variable nx index 100
variable ny index 58
variable notch index 20
variable rate index 1.0e-3
variable T index 0.001
variable damp index 1.0
variable dt index 0.005
variable seed index 48279
variable strain_max index 0.2
variable rb index __RB__
variable rcut equal __RCUT__
variable nprint index 100
variable sparse index 4000
variable dense index 200
variable extra index 4000
units           lj
dimension       2
atom_style      atomic
boundary        s s p
variable        a0 file ${out}/../a0.txt
lattice         hex $(2.0/(sqrt(3.0)*v_a0*v_a0))
region          box block 0 ${nx} 0 ${ny} -0.5 0.5
create_box      3 box
region          cells block -0.01 $(v_nx-0.01) -0.01 $(v_ny-0.01) -0.5 0.5
create_atoms    1 region cells
mass            * 1.0
include         ${out}/../potential.mod
__CUT__
variable        h equal sqrt(3.0)/2.0*${a0}
variable        W equal ${nx}*${a0}
variable        yc equal (${ny}-0.5)*${h}
variable        a equal ${notch}*${a0}
region          nabove block INF $(v_a-0.25*v_a0) ${yc} $(v_yc+v_rcut) INF INF units box
region          nbelow block INF $(v_a-0.25*v_a0) $(v_yc-v_rcut) ${yc} INF INF units box
set             region nabove type 2
set             region nbelow type 3
variable        ybot equal 1.5*${h}
variable        ytop equal (2*${ny}-2.5)*${h}
region          rbot block INF INF INF ${ybot} INF INF units box
region          rtop block INF INF ${ytop} INF INF INF units box
group           bot region rbot
group           top region rtop
group           grips union bot top
group           free subtract all grips
variable        L0 equal (2*${ny}-2)*${h}
variable        v equal ${rate}*${L0}
neighbor        0.3 bin
neigh_modify    every 1 delay 0 check yes
timestep        ${dt}
velocity        all set 0 0 0
velocity        free ramp vy 0 ${v} y $(0.5*v_h) $((2*v_ny-1.5)*v_h) units box
velocity        top set 0 ${v} 0 units box
fix             nve all nve
fix             clampb bot setforce NULL 0 0
fix             pull top setforce NULL 0 0
# the bath acts on v_x only (temp/partial as its bias): a Langevin drag on v_y would resist the
# streaming velocity of the stretched sheet (sum m v_y / damp, of the order of the fracture load)
compute         tx free temp/partial 1 0 0
fix             bath free langevin ${T} ${T} ${damp} ${seed}
fix_modify      bath temp tx
fix             2d all enforce2d
compute         coord all coord/atom cutoff ${rb}
variable        inner atom (x>xlo+2.0)*(x<xhi-2.0)*(y>ylo+2.0)*(y<yhi-2.0)
variable        tipatom atom v_inner*(c_coord<6)*x
variable        defatom atom v_inner*(c_coord!=6)*(abs(y-v_yc)>3*v_h)
compute         tipmax all reduce max v_tipatom
compute         ndef all reduce sum v_defatom
variable        tip equal c_tipmax
variable        ndefects equal c_ndef
variable        strain equal (step*${dt})*${rate}
variable        stress equal -f_pull[2]/${W}
variable        nsteps equal round(${strain_max}/(${rate}*${dt}))
variable        natoms equal count(all)
variable        toend equal v_tip-(xhi-4.0)
print           "L0 ${L0} W ${W} a0 ${a0} atoms ${natoms} rate ${rate} dt ${dt} notch ${notch} a ${a} T ${T} damp ${damp} yc ${yc} h ${h} nx ${nx} ny ${ny} rb ${rb}" file ${out}/meta.txt screen no
fix             out all print ${nprint} "$(step) ${strain} ${stress} ${tip} ${ndefects} $(temp)" file ${out}/series.txt screen no title "# step strain nominal_stress tip_x defects temp"
thermo_style    custom step v_strain v_stress v_tip v_ndefects temp pe
thermo          2000
# dumps: every `sparse` steps, every `dense` steps once the crack has run 3 a0 past the notch
variable        running equal v_tip>(${a}+3*${a0})
variable        nextdump equal step+${sparse}-v_running*(${sparse}-${dense})
dump            dd all custom ${sparse} ${out}/frames.dump id type x y c_coord
dump_modify     dd sort id every v_nextdump first yes
# load until the crack is within 4 sigma of the right edge (or strain_max), then `extra` steps
fix             h all halt ${nprint} v_toend > 0.0 error continue
run             ${nsteps} upto
unfix           h
if "$(step) < ${nsteps}" then "run ${extra}"
print           "done step $(step) strain ${strain}" append ${out}/meta.txt screen no
"""

GRIFFITH = """# Energy release rate of the notched sheet of in.fracture at T = 0, by molecular statics: the
# same sheet, notch and grips; the sheet is minimised unstrained (U0), then stretched by an affine
# displacement (strain eps: the top grip moved by eps L0) and minimised with the grips held in y
# and free in x (U1). Pi = U1 - U0 is the stored elastic energy (for nearest-neighbour models U0
# is the bond count times the bond energy; it cancels the bonds the notch removes). At fixed grips
# G = -dPi/da (griffith.py: central difference in a). Writes a line to ${out}/griffith.txt:
#   notch a U0 U1 Pi stress(=grip force / W at eps) eps fnorm
# Run: lmp -in in.griffith -var out <dir> -var nx .. -var ny .. -var notch .. -var eps ..
variable out index .
variable nx index 100
variable ny index 58
variable notch index 20
variable eps index 0.002
variable rcut equal __RCUT__
units           lj
dimension       2
atom_style      atomic
boundary        s s p
variable        a0 file ${out}/a0.txt
lattice         hex $(2.0/(sqrt(3.0)*v_a0*v_a0))
region          box block 0 ${nx} 0 ${ny} -0.5 0.5
create_box      3 box
region          cells block -0.01 $(v_nx-0.01) -0.01 $(v_ny-0.01) -0.5 0.5
create_atoms    1 region cells
mass            * 1.0
include         ${out}/potential.mod
__CUT__
variable        h equal sqrt(3.0)/2.0*${a0}
variable        W equal ${nx}*${a0}
variable        yc equal (${ny}-0.5)*${h}
variable        a equal ${notch}*${a0}
region          nabove block INF $(v_a-0.25*v_a0) ${yc} $(v_yc+v_rcut) INF INF units box
region          nbelow block INF $(v_a-0.25*v_a0) $(v_yc-v_rcut) ${yc} INF INF units box
set             region nabove type 2
set             region nbelow type 3
variable        ybot equal 1.5*${h}
variable        ytop equal (2*${ny}-2.5)*${h}
region          rbot block INF INF INF ${ybot} INF INF units box
region          rtop block INF INF ${ytop} INF INF INF units box
group           bot region rbot
group           top region rtop
variable        L0 equal (2*${ny}-2)*${h}
fix             clampb bot setforce NULL 0 0
fix             pull top setforce NULL 0 0
fix             2d all enforce2d
thermo_style    custom step pe fnorm
thermo_modify   norm no
min_style       cg
# the unstrained sheet: edges relax (nothing to do for nearest-neighbour models, |f| ~ 1e-10)
minimize        0.0 1.0e-8 10000 100000
variable        U0 equal $(pe:%.17g)
# affine stretch: zero at the bottom grip's centre (y = h/2), eps L0 at the top grip's centre
displace_atoms  all ramp y 0.0 $(v_eps*v_L0) y $(0.5*v_h) $(0.5*v_h+v_L0) units box
minimize        0.0 1.0e-8 100000 1000000
variable        U1 equal $(pe:%.17g)
variable        sig equal $(-f_pull[2]/v_W:%.17g)
print           "${notch} ${a} ${U0} ${U1} $(v_U1-v_U0:%.17g) ${sig} ${eps} $(fnorm:%.3g)" append ${out}/griffith.txt screen no
"""


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--system", required=True, choices=sorted(SYSTEMS))
    ap.add_argument("dir")
    o = ap.parse_args()
    pot, cut, rc = SYSTEMS[o.system]
    os.makedirs(o.dir, exist_ok=True)
    with open(os.path.join(o.dir, "potential.mod"), "w") as f:
        f.write(f"# {o.system}: written by make_decks.py\n{pot}")
    for name, text in (("in.relax", RELAX), ("in.surface", SURFACE)):
        with open(os.path.join(o.dir, name), "w") as f:
            f.write(text)
    rb = 1.5  # bond 'broken' beyond 1.5 sigma: past the inflection (1.245), inside the second shell (1.93)
    with open(os.path.join(o.dir, "in.fracture"), "w") as f:
        f.write(FRACTURE.replace("__CUT__", cut).replace("__RB__", repr(rb)).replace("__RCUT__", repr(rc)))
    with open(os.path.join(o.dir, "in.griffith"), "w") as f:
        f.write(GRIFFITH.replace("__CUT__", cut).replace("__RCUT__", repr(rc)))
    with open(os.path.join(o.dir, "system.txt"), "w") as f:
        f.write(f"{o.system} {rc}\n")


if __name__ == "__main__":
    main()
