!> The Appendix B memory map (Tables B.1 and B.2).
module test_workspace
   use femcod_kinds, only: dp, i8
   use femcod_status, only: status_type
   use femcod_workspace, only: workspace_type, workspace_layout, allocate_workspace, skyline_words, workspace_table, &
      MPSURF, MPGAPS, MPCORD, MPFEXT, MPDISP, MPDISP2, MPFORCE, MPWORK, MPSTIF, IPSORT, IPSITU, IPCONT
   use test_support, only: contains_text
   use femcod_thesis, only: TABLE_B_NP, TABLE_B_MAXCONT, TABLE_B_1_SIZES, TABLE_B_1_STIFFNESS, TABLE_B_1_MPEND, &
      TABLE_B_2_IPEND
   use testdrive, only: new_unittest, unittest_type, error_type, check, to_string
   implicit none
   private
   public :: collect_workspace

contains

   subroutine collect_workspace(testsuite)
      type(unittest_type), allocatable, intent(out) :: testsuite(:)
      testsuite = [ &
         new_unittest("Table B.2: IPEND = 284156 for NP=512, MAXCONT=1000", test_ipend), &
         new_unittest("Table B.1: real block sizes and MPEND = 3981268", test_real_blocks), &
         new_unittest("blocks are contiguous and bounds are checked", test_contiguous), &
         new_unittest("skyline size rule: (7n+2)(n+1)/2", test_skyline_rule), &
         new_unittest("too large a workspace: bytes needed, no crash", test_too_large), &
         new_unittest("the printed table (femcod workspace 512 1000)", test_printed_table) &
         ]
   end subroutine collect_workspace

   subroutine test_ipend(error)
      type(error_type), allocatable, intent(out) :: error
      type(workspace_type) :: ws
      type(status_type) :: status
      ! Thesis Table B.2 (femcod_thesis): "IPEND = 284156 for 1000 contact problem".
      call workspace_layout(TABLE_B_NP, TABLE_B_MAXCONT, ws, status)
      call check(error, int(ws%ipend), int(TABLE_B_2_IPEND))
   end subroutine test_ipend

   subroutine test_real_blocks(error)
      type(error_type), allocatable, intent(out) :: error
      type(workspace_type) :: ws
      type(status_type) :: status
      integer :: k
      ! Thesis Table B.1 (femcod_thesis) with its largest stiffness block: the printed block
      ! sizes and MPEND.
      call workspace_layout(TABLE_B_NP, TABLE_B_MAXCONT, ws, status, stiffness_words=TABLE_B_1_STIFFNESS)
      do k = MPSURF, MPWORK
         call check(error, int(ws%real_blocks(k)%size), int(TABLE_B_1_SIZES(k)), "size of "//ws%real_blocks(k)%name)
         if (allocated(error)) return
      end do
      call check(error, int(ws%mpend), int(TABLE_B_1_MPEND), "MPEND as printed in Table B.1")
   end subroutine test_real_blocks

   subroutine test_contiguous(error)
      type(error_type), allocatable, intent(out) :: error
      type(workspace_type) :: ws
      type(status_type) :: status
      integer :: k, a
      call workspace_layout(16, 20, ws, status)
      call allocate_workspace(ws, status)
      call check(error, status%code, 0)
      if (allocated(error)) return
      do k = MPGAPS, MPSTIF
         call check(error, ws%real_blocks(k)%first == ws%real_blocks(k - 1)%first + ws%real_blocks(k - 1)%size, &
            "real block follows its predecessor: "//ws%real_blocks(k)%name)
         if (allocated(error)) return
      end do
      call check(error, size(ws%ra) == ws%mpend .and. size(ws%ia) == ws%ipend, "arrays sized to MPEND, IPEND")
      if (allocated(error)) return
      call check(error, ws%rfirst(MPGAPS) == 2*16*16 + 1 .and. ws%rlast(MPGAPS) == 3*16*16, "MPGAPS range")
      if (allocated(error)) return
      call check(error, ws%ifirst(IPSORT) == 1 .and. ws%ilast(IPSITU) == ws%ipend, "integer range")
      if (allocated(error)) return
      a = ws%raddr(MPGAPS, 256, status)
      call check(error, a == ws%rlast(MPGAPS) .and. status%code == 0, "last word of MPGAPS")
      if (allocated(error)) return
      a = ws%iaddr(IPCONT, 21, status)
      call check(error, a == 0 .and. status%code /= 0 .and. contains_text(status%message, "IPCONT"), &
         "word 21 of IPCONT (MAXCONT = 20) is refused")
   end subroutine test_contiguous

   subroutine test_skyline_rule(error)
      type(error_type), allocatable, intent(out) :: error
      integer :: n, k
      integer(i8) :: words
      ! Independent count: sum the column heights of the numbering rule + diagonals.
      do n = 1, 40
         words = 4*n + 1
         do k = 1, n
            words = words + (k - 1) + (n + k - 1) + 1 + (2*n - k)
         end do
         words = words + n
         call check(error, skyline_words(n) == words, "skyline words for n = "//trim(adjustl(itoa(n))))
         if (allocated(error)) return
      end do
   contains
      function itoa(i) result(s)
         integer, intent(in) :: i
         character(len=12) :: s
         write(s, '(i0)') i
      end function itoa
   end subroutine test_skyline_rule

   subroutine test_too_large(error)
      type(error_type), allocatable, intent(out) :: error
      type(workspace_type) :: ws
      type(status_type) :: status
      call workspace_layout(40000, 100000, ws, status)
      call check(error, status%code, 0)
      if (allocated(error)) return
      call allocate_workspace(ws, status)
      call check(error, status%code == 4 .and. contains_text(status%message, "bytes"), &
         "refused with the bytes needed: "//status%message)
   end subroutine test_too_large

   subroutine test_printed_table(error)
      type(error_type), allocatable, intent(out) :: error
      type(workspace_type) :: ws
      type(status_type) :: status
      character(len=120), allocatable :: lines(:)
      integer :: k
      logical :: found(4)
      call workspace_layout(TABLE_B_NP, TABLE_B_MAXCONT, ws, status)
      lines = workspace_table(ws)
      found = .false.
      associate(ipend => int(TABLE_B_2_IPEND), np2 => TABLE_B_NP**2, mpcord => int(TABLE_B_1_SIZES(3)))
         do k = 1, size(lines)
            ! Table B.2 (femcod_thesis): IPSORT first at 1 with NP^2 words; IPEND.
            if (index(lines(k), "IPSORT") == 1 .and. index(lines(k), " 1 ") > 0 .and. &
               index(lines(k), to_string(np2)) > 0) found(1) = .true.
            if (index(lines(k), "IPEND") == 1 .and. index(lines(k), to_string(ipend)) > 0) found(2) = .true.
            ! IPEND default integers of 4 bytes each.
            if (index(lines(k), "total integer: "//to_string(ipend)//" words, "//to_string(4*ipend)//" bytes") == 1) &
               found(3) = .true.
            ! MPCORD as the thesis prints it (Table B.1).
            if (index(lines(k), "MPCORD") == 1 .and. index(lines(k), to_string(mpcord)) > 0) found(4) = .true.
         end do
      end associate
      call check(error, all(found), "IPSORT, IPEND, integer total and MPCORD lines as expected")
   end subroutine test_printed_table
end module test_workspace
