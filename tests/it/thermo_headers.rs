//! Thermo column headers as the engines print them: LIGGGHTS 3.8 shows a
//! c_/f_/v_ column by its name without the prefix, cut to 8 characters
//! (`f_heattransfer` is `heattran`); a header that differs made a real deck
//! (elizabeth-suehr heatTransfer_1) differ from the engine.

use crate::common;

const DECK: &str = "\
atom_style granular
atom_modify map array
boundary f f f
newton off
communicate single vel yes
units si
region reg block 0 0.01 0 0.01 0 0.01 units box
create_box 1 reg
neighbor 0.0002 bin
fix m1 all property/global youngsModulus peratomtype 1.e7
fix m2 all property/global poissonsRatio peratomtype 0.3
fix m3 all property/global coefficientRestitution peratomtypepair 1 0.5
fix m4 all property/global coefficientFriction peratomtypepair 1 0.5
pair_style gran model hertz tangential history
pair_coeff * *
timestep 1e-6
create_atoms 1 single 0.005 0.005 0.005 units box
set atom 1 diameter 0.002 density 2500
fix integr all nve/sphere
compute rke all erotate/sphere
compute averyverylongname all erotate/sphere
compute centreofmass all com
compute cm all com
variable longvariablename equal 2*step
thermo_style custom step atoms ke c_rke c_averyverylongname c_centreofmass[3] c_cm[3] v_longvariablename vol
run 10
";

#[test]
fn liggghts_headers_drop_the_prefix_and_keep_eight_characters() {
    let b = common::engine_and_demx("liggghts", "in.deck", &[("in.deck", DECK)]);
    let header =
        |out: &str| out.lines().find(|l| l.trim_start().starts_with("Step ")).map(|l| l.split_whitespace().map(String::from).collect::<Vec<_>>());
    let theirs = header(&b.theirs_out).expect("LIGGGHTS printed a header");
    assert_eq!(theirs, ["Step", "Atoms", "KinEng", "rke", "averyver", "centreof", "cm[3]", "longvari", "Volume"], "LIGGGHTS 3.8's own header");
    assert_eq!(header(&b.ours_out).as_ref(), Some(&theirs));
    assert_eq!(common::thermo_runs(&b.theirs_out), common::thermo_runs(&b.ours_out), "and the rows");
}
