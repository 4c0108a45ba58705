!> The FEMCOD work arrays of Appendix B: one integer and one real array, each cut
!> into named blocks addressed by memory pointers (Tables B.1 and B.2).
!>
!> Addresses are 1-based. `first` is the first address of a block, `size` its length
!> in words; the end markers IPEND and MPEND are the last address in use, i.e. the
!> total number of words, which is how the thesis prints them (IPEND = 284156 for
!> NP = 512, MAXCONT = 1000). Sizes follow the tables with MAXNODE = 4*MAXCONT + 2,
!> with two documented choices (doc/workspace.md):
!>  - MPCORD holds 3*MAXNODE + 2 words: the table says 3xMAXNODE but prints 12008
!>    for MAXNODE = 4002 and its MPEND total is only consistent with 12008, so the
!>    original code allocated two spare words; femcod follows the code.
!>  - MPSTIF is the skyline size of femcod's equation numbering at MAXCONT
!>    contacts, (7*MAXCONT + 2)*(MAXCONT + 1)/2 words (see `skyline_words`).
module femcod_workspace
   use femcod_memory, only: memory_text, usable_text
   use femcod_kinds, only: dp, i8
   use femcod_status, only: status_type, set_error, STATUS_NUMERICAL, STATUS_BAD_INPUT
   use femcod_strings, only: int_str
   implicit none
   private
   public :: workspace_type, block_type, workspace_layout, allocate_workspace, skyline_words, workspace_table
   public :: MAX_WORKSPACE_CONTACTS
   public :: MPSURF, MPGAPS, MPCORD, MPFEXT, MPDISP, MPDISP2, MPFORCE, MPWORK, MPSTIF, N_REAL_BLOCKS
   public :: IPSORT, IPKFIX, IPMAT, IPMAT2, IPMAT3, IPIADR, IPNOD1, IPNOD2, IPNOD3, IPCONT, IPSITU, N_INT_BLOCKS

   !> The most contacts a map is drawn for: MAXNODE = 4 MAXCONT + 2 is an integer word
   !> (Appendix B's node numbers), so MAXCONT <= (huge - 2)/4.
   integer, parameter :: MAX_WORKSPACE_CONTACTS = (huge(1) - 2)/4

   !> Real blocks (Table B.1), in address order.
   integer, parameter :: MPSURF = 1, MPGAPS = 2, MPCORD = 3, MPFEXT = 4, MPDISP = 5, MPDISP2 = 6, &
      MPFORCE = 7, MPWORK = 8, MPSTIF = 9, N_REAL_BLOCKS = 9
   !> Integer blocks (Table B.2), in address order.
   integer, parameter :: IPSORT = 1, IPKFIX = 2, IPMAT = 3, IPMAT2 = 4, IPMAT3 = 5, IPIADR = 6, IPNOD1 = 7, &
      IPNOD2 = 8, IPNOD3 = 9, IPCONT = 10, IPSITU = 11, N_INT_BLOCKS = 11

   !> One block of a work array.
   type :: block_type
      character(len=8) :: name = ""
      !> First address (1-based).
      integer(i8) :: first = 0
      !> Length in words.
      integer(i8) :: size = 0
      character(len=80) :: holds = ""
   end type block_type

   !> The two work arrays and their memory map.
   type :: workspace_type
      integer :: np = 0, maxcont = 0, maxnode = 0
      type(block_type) :: real_blocks(N_REAL_BLOCKS)
      type(block_type) :: int_blocks(N_INT_BLOCKS)
      !> MPEND and IPEND: last address in use (= words).
      integer(i8) :: mpend = 0, ipend = 0
      real(dp), allocatable :: ra(:)
      integer, allocatable :: ia(:)
   contains
      procedure :: rfirst, rlast, ifirst, ilast, raddr, iaddr
   end type workspace_type

contains

   !> Words of femcod's skyline for `ncont` contacts (diagonal included). Equations:
   !> b1(1..n) lower substrate, then (s1(k), s2(k)) surface pairs, b2(1..n) upper
   !> substrate, top handle; the bottom handle is fixed and eliminated. Column heights:
   !> b1(k): k-1; s1(k): n+k-1; s2(k): 1; b2(k): 2n-k; handle: n; their sum plus the
   !> 4n+1 diagonals is (7n+2)(n+1)/2.
   pure integer(i8) function skyline_words(ncont)
      integer, intent(in) :: ncont
      integer(i8) :: n
      n = ncont
      skyline_words = (7*n + 2)*(n + 1)/2
   end function skyline_words

   !> The memory map for NP and MAXCONT; `stiffness_words` overrides the MPSTIF size
   !> (used to compare with the thesis' printed 2121244).
   subroutine workspace_layout(np, maxcont, ws, status, stiffness_words)
      integer, intent(in) :: np, maxcont
      type(workspace_type), intent(out) :: ws
      type(status_type), intent(inout) :: status
      integer(i8), intent(in), optional :: stiffness_words
      integer(i8) :: np2, mc, mn, stif
      integer :: k
      if (np <= 0 .or. maxcont <= 0) then
         call set_error(status, STATUS_BAD_INPUT, "workspace: NP and MAXCONT must be positive")
         return
      end if
      if (maxcont > MAX_WORKSPACE_CONTACTS) then
         call set_error(status, STATUS_BAD_INPUT, "workspace: MAXCONT above "//int_str(MAX_WORKSPACE_CONTACTS)// &
            " makes MAXNODE = 4 MAXCONT + 2 overflow an integer word")
         return
      end if
      np2 = int(np, i8)**2
      if (maxcont > np2) then
         call set_error(status, STATUS_BAD_INPUT, "workspace: MAXCONT must not exceed NP**2")
         return
      end if
      mc = maxcont
      mn = 4*mc + 2
      ws%np = np
      ws%maxcont = maxcont
      ws%maxnode = int(mn)
      stif = skyline_words(maxcont)
      if (present(stiffness_words)) stif = stiffness_words
      ws%real_blocks(MPSURF) = block_type("MPSURF", 0, 2*np2, "lower and upper surface heights (nm)")
      ws%real_blocks(MPGAPS) = block_type("MPGAPS", 0, np2, "initial gaps, at the first touch (nm)")
      ws%real_blocks(MPCORD) = block_type("MPCORD", 0, 3*mn + 2, "node coordinates x, y, z (nm)")
      ws%real_blocks(MPFEXT) = block_type("MPFEXT", 0, mn, "external loads by node (nN)")
      ws%real_blocks(MPDISP) = block_type("MPDISP", 0, mn, "displacements under the unit load (nm/nN)")
      ws%real_blocks(MPDISP2) = block_type("MPDISP2", 0, 4*np2 + 2, "displacement of every pixel at the last contact (nm)")
      ws%real_blocks(MPFORCE) = block_type("MPFORCE", 0, mc, "total contact (spring) forces (nN)")
      ws%real_blocks(MPWORK) = block_type("MPWORK", 0, mn, "work: TRFACT residual, contact forces per nN")
      ws%real_blocks(MPSTIF) = block_type("MPSTIF", 0, stif, "skyline stiffness matrix (nN/nm)")
      ws%int_blocks(IPSORT) = block_type("IPSORT", 0, np2, "pixel numbers in ascending order of gap")
      ws%int_blocks(IPKFIX) = block_type("IPKFIX", 0, mn, "fixed-d.o.f. flags of the nodes (1: fixed)")
      ws%int_blocks(IPMAT) = block_type("IPMAT", 0, 2, "material numbers of the Boussinesq elements")
      ws%int_blocks(IPMAT2) = block_type("IPMAT2", 0, 2, "material numbers of the interface springs")
      ws%int_blocks(IPMAT3) = block_type("IPMAT3", 0, 2, "material numbers of the penalty springs")
      ws%int_blocks(IPIADR) = block_type("IPIADR", 0, mn, "diagonal addresses in the skyline")
      ws%int_blocks(IPNOD1) = block_type("IPNOD1", 0, 2*mc + 2, "element type 1 connectivity")
      ws%int_blocks(IPNOD2) = block_type("IPNOD2", 0, 4*mc, "element type 2 connectivity")
      ws%int_blocks(IPNOD3) = block_type("IPNOD3", 0, 2*mc, "element type 3 connectivity")
      ws%int_blocks(IPCONT) = block_type("IPCONT", 0, mc, "contact pixel numbers, in order of contact")
      ws%int_blocks(IPSITU) = block_type("IPSITU", 0, 5*mc, "in contact (1) or not (0), first 5*MAXCONT gaps")
      ws%real_blocks(1)%first = 1
      do k = 2, N_REAL_BLOCKS
         ws%real_blocks(k)%first = ws%real_blocks(k - 1)%first + ws%real_blocks(k - 1)%size
      end do
      ws%mpend = ws%real_blocks(N_REAL_BLOCKS)%first + ws%real_blocks(N_REAL_BLOCKS)%size - 1
      ws%int_blocks(1)%first = 1
      do k = 2, N_INT_BLOCKS
         ws%int_blocks(k)%first = ws%int_blocks(k - 1)%first + ws%int_blocks(k - 1)%size
      end do
      ws%ipend = ws%int_blocks(N_INT_BLOCKS)%first + ws%int_blocks(N_INT_BLOCKS)%size - 1
   end subroutine workspace_layout

   !> The memory map as printed by `femcod workspace`: a header, one line per block
   !> (name, first address, words, contents), the end markers, the totals in words and bytes.
   function workspace_table(ws) result(lines)
      type(workspace_type), intent(in) :: ws
      character(len=120), allocatable :: lines(:)
      character(len=120) :: line
      integer :: k
      allocate(lines(0))
      write(line, '(a,i0,a,i0,a,i0)') "# femcod workspace: NP = ", ws%np, ", MAXCONT = ", ws%maxcont, &
         ", MAXNODE = ", ws%maxnode
      lines = [character(len=120) :: lines, line, "# integer array (Table B.2)"]
      write(line, '(a8,2a14,2x,a)') "block", "first", "words", "holds"
      lines = [character(len=120) :: lines, line]
      do k = 1, N_INT_BLOCKS
         write(line, '(a8,2i14,2x,a)') ws%int_blocks(k)%name, ws%int_blocks(k)%first, ws%int_blocks(k)%size, &
            trim(ws%int_blocks(k)%holds)
         lines = [character(len=120) :: lines, line]
      end do
      write(line, '(a8,i14,14x,2x,a)') "IPEND   ", ws%ipend, "last address in use = integer words"
      lines = [character(len=120) :: lines, line, "# real array (Table B.1)"]
      write(line, '(a8,2a14,2x,a)') "block", "first", "words", "holds"
      lines = [character(len=120) :: lines, line]
      do k = 1, N_REAL_BLOCKS
         write(line, '(a8,2i14,2x,a)') ws%real_blocks(k)%name, ws%real_blocks(k)%first, ws%real_blocks(k)%size, &
            trim(ws%real_blocks(k)%holds)
         lines = [character(len=120) :: lines, line]
      end do
      write(line, '(a8,i14,14x,2x,a)') "MPEND   ", ws%mpend, "last address in use = real words"
      lines = [character(len=120) :: lines, line]
      write(line, '(a,i0,a,i0,a)') "total integer: ", ws%ipend, " words, ", 4*ws%ipend, " bytes"
      lines = [character(len=120) :: lines, line]
      write(line, '(a,i0,a,i0,a)') "total real: ", ws%mpend, " words, ", 8*ws%mpend, " bytes"
      lines = [character(len=120) :: lines, line]
      write(line, '(a,i0,a)') "total: ", 4*ws%ipend + 8*ws%mpend, " bytes"
      lines = [character(len=120) :: lines, line]
   end function workspace_table

   !> Allocate both arrays (zeroed). A failed allocation is reported with the bytes
   !> needed, never a crash.
   subroutine allocate_workspace(ws, status, memory_available)
      type(workspace_type), intent(inout) :: ws
      type(status_type), intent(inout) :: status
      !> The bytes this run may use (the caller asks the system: the numerical layers do
      !> no I/O); absent or 0: not checked.
      integer(i8), intent(in), optional :: memory_available
      integer(i8) :: budget
      integer :: stat
      character(len=40) :: buf
      if (ws%mpend > huge(1) .or. ws%ipend > huge(1)) then
         write(buf, '(i0)') 8*ws%mpend + 4*ws%ipend
         call set_error(status, STATUS_NUMERICAL, "workspace: needs "//trim(buf)// &
            " bytes, more words than one array can address")
         return
      end if
      budget = 0
      if (present(memory_available)) budget = memory_available
      if (budget > 0 .and. 8*ws%mpend + 4*ws%ipend > budget) then
         call set_error(status, STATUS_NUMERICAL, "workspace: needs "//memory_text(8*ws%mpend + 4*ws%ipend)// &
            ", this run may use "//usable_text(budget))
         return
      end if
      allocate(ws%ra(ws%mpend), ws%ia(ws%ipend), stat=stat)
      if (stat /= 0) then
         write(buf, '(i0)') 8*ws%mpend + 4*ws%ipend
         call set_error(status, STATUS_NUMERICAL, "workspace: cannot allocate "//trim(buf)//" bytes")
         return
      end if
      ws%ra = 0
      ws%ia = 0
   end subroutine allocate_workspace

   !> First and last address of a real block.
   pure integer function rfirst(ws, block)
      class(workspace_type), intent(in) :: ws
      integer, intent(in) :: block
      rfirst = int(ws%real_blocks(block)%first)
   end function rfirst
   pure integer function rlast(ws, block)
      class(workspace_type), intent(in) :: ws
      integer, intent(in) :: block
      rlast = int(ws%real_blocks(block)%first + ws%real_blocks(block)%size - 1)
   end function rlast
   pure integer function ifirst(ws, block)
      class(workspace_type), intent(in) :: ws
      integer, intent(in) :: block
      ifirst = int(ws%int_blocks(block)%first)
   end function ifirst
   pure integer function ilast(ws, block)
      class(workspace_type), intent(in) :: ws
      integer, intent(in) :: block
      ilast = int(ws%int_blocks(block)%first + ws%int_blocks(block)%size - 1)
   end function ilast

   !> Address of word k (1-based) of a real block; 0 and an error when k is outside it.
   integer function raddr(ws, block, k, status)
      class(workspace_type), intent(in) :: ws
      integer, intent(in) :: block, k
      type(status_type), intent(inout) :: status
      raddr = 0
      if (k < 1 .or. k > ws%real_blocks(block)%size) then
         call set_error(status, STATUS_NUMERICAL, "workspace: index outside block "// &
            trim(ws%real_blocks(block)%name))
         return
      end if
      raddr = int(ws%real_blocks(block)%first) + k - 1
   end function raddr

   !> Address of word k (1-based) of an integer block; 0 and an error when outside.
   integer function iaddr(ws, block, k, status)
      class(workspace_type), intent(in) :: ws
      integer, intent(in) :: block, k
      type(status_type), intent(inout) :: status
      iaddr = 0
      if (k < 1 .or. k > ws%int_blocks(block)%size) then
         call set_error(status, STATUS_NUMERICAL, "workspace: index outside block "// &
            trim(ws%int_blocks(block)%name))
         return
      end if
      iaddr = int(ws%int_blocks(block)%first) + k - 1
   end function iaddr
end module femcod_workspace
