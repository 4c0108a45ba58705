!> The numbers the thesis publishes that femcod is checked against, typed in once:
!> `femcod verify` (doc/verification.md) and the test suite both read them from here.
!> Every value is quoted from K. C. Bora, "Analytical and numerical modeling of contact
!> using atomic force microscopy images", UW-Madison 2012, at the place named; lengths
!> in nm, loads in nN, pressures in GPa (= nN/nm^2).
module femcod_thesis
   use femcod_kinds, only: dp, i8
   implicit none
   private
   public :: TABLE_4_1_DECKS, TABLE_4_1_PIXELS, TABLE_4_1_MESH, TABLE_4_1_APPROACH, TABLE_4_1_CENTRE_PRESSURE
   public :: TABLE_4_1_RATE, TABLE_4_1_ANALYTIC_APPROACH
   public :: TABLE_4_2_DECKS, TABLE_4_2_APPROACH, TABLE_4_2_CENTRE_OVER_MEAN, TABLE_4_2_RATE_13, TABLE_4_2_RATE_24
   public :: TABLE_4_2_EXTRAPOLATED_APPROACH, TABLE_4_2_EXTRAPOLATED_RATIO, BORODACHEV_APPROACH, BORODACHEV_RATIO
   public :: SPHERE_FIT_EXPONENT, PIXEL_COMPLIANCE, FIG_5_2_PERCENT, FIG_5_2_PERMILLE
   public :: TABLE_B_NP, TABLE_B_MAXCONT, TABLE_B_1_SIZES, TABLE_B_1_STIFFNESS, TABLE_B_1_MPEND, TABLE_B_2_IPEND
   public :: PRINTED_DIGITS

   !> The thesis prints three significant digits.
   integer, parameter :: PRINTED_DIGITS = 3

   !> Table 4.1: rigid circular punch of 21 nm^2 on E = 200 GPa, nu = 0.25, at 1 nN, for
   !> meshes of 1, 1/3 and 1/9 nm (the decks of input/): approach (nm) and the centre
   !> pixel's pressure (GPa).
   character(len=*), parameter :: TABLE_4_1_DECKS(3) = [character(len=15) :: "circle_punch_d1", "circle_punch_d3", &
      "circle_punch_d9"]
   integer, parameter :: TABLE_4_1_PIXELS(3) = [21, 189, 1701]
   character(len=*), parameter :: TABLE_4_1_MESH(3) = [character(len=3) :: "1", "1/3", "1/9"]
   real(dp), parameter :: TABLE_4_1_APPROACH(3) = [0.955e-3_dp, 0.920e-3_dp, 0.911e-3_dp]
   real(dp), parameter :: TABLE_4_1_CENTRE_PRESSURE(3) = [0.0261_dp, 0.0245_dp, 0.0240_dp]
   !> Section 4.4.1: the Richardson rate of the circle's displacements, and the analytic
   !> displacement of eq. 4.10 with the radius of the discretised area (nm).
   real(dp), parameter :: TABLE_4_1_RATE = 1.15_dp, TABLE_4_1_ANALYTIC_APPROACH = 0.907e-3_dp

   !> Table 4.2: rigid square punch of 10 nm in a 30 nm region at 1 nN, NP = 3, 9, 27, 81:
   !> approach (nm) and centre pressure over mean pressure.
   character(len=*), parameter :: TABLE_4_2_DECKS(4) = [character(len=16) :: "square_punch_n1", "square_punch_n3", &
      "square_punch_n9", "square_punch_n27"]
   real(dp), parameter :: TABLE_4_2_APPROACH(4) = [0.526e-3_dp, 0.451e-3_dp, 0.422e-3_dp, 0.412e-3_dp]
   real(dp), parameter :: TABLE_4_2_CENTRE_OVER_MEAN(4) = [1.0_dp, 0.511_dp, 0.519_dp, 0.498_dp]
   !> Section 4.4.2: Richardson rates of the approach from meshes 1-3 and 2-4, the
   !> extrapolated approach (nm) and centre/mean pressure, and Borodachev's approximate
   !> solution.
   real(dp), parameter :: TABLE_4_2_RATE_13 = 0.874_dp, TABLE_4_2_RATE_24 = 0.973_dp
   real(dp), parameter :: TABLE_4_2_EXTRAPOLATED_APPROACH = 0.407e-3_dp, TABLE_4_2_EXTRAPOLATED_RATIO = 0.486_dp
   real(dp), parameter :: BORODACHEV_APPROACH = 0.400e-3_dp, BORODACHEV_RATIO = 0.456_dp

   !> Section 4.4.3: the exponent of the area-load power law fitted to the 0.5 nm sphere.
   real(dp), parameter :: SPHERE_FIT_EXPONENT = 0.68_dp

   !> Section 4.5: the single-pixel compliance (nm/nN) of E = 200 GPa, nu = 0.25,
   !> d = 5000/512 nm (the "stiffness" of the 512 x 512 image).
   real(dp), parameter :: PIXEL_COMPLIANCE = 5.39e-4_dp
   !> Fig. 5.2: the surface displacement at n pixels falls below 1/100 of the centre's
   !> between n = 28 and 29, below 1/1000 between 283 and 284.
   integer, parameter :: FIG_5_2_PERCENT = 28, FIG_5_2_PERMILLE = 283

   !> Tables B.1 and B.2 are printed for NP = 512, MAXCONT = 1000.
   integer, parameter :: TABLE_B_NP = 512, TABLE_B_MAXCONT = 1000
   !> Table B.1: the printed sizes of MPSURF, MPGAPS, MPCORD, MPFEXT, MPDISP, MPDISP2,
   !> MPFORCE, MPWORK; the stiffness block "of the largest size"; MPEND.
   integer(i8), parameter :: TABLE_B_1_SIZES(8) = [524288_i8, 262144_i8, 12008_i8, 4002_i8, 4002_i8, 1048578_i8, &
      1000_i8, 4002_i8]
   integer(i8), parameter :: TABLE_B_1_STIFFNESS = 2121244_i8, TABLE_B_1_MPEND = 3981268_i8
   !> Table B.2: IPEND.
   integer(i8), parameter :: TABLE_B_2_IPEND = 284156_i8
end module femcod_thesis
