"""The instruction names of the Q CPUs (QnU), which GX Works2 refuses as label names in a
QCPU (Q mode) project (docs/st-dialect.md section 4).

Source: MELSEC-Q/L Programming Manual (Common Instruction) (SH-080809ENG), chapter 2
"Instruction Tables": sequence instructions, basic instructions, application
instructions, data link and QnU-specific instructions. One line an instruction: its
mnemonic, then `d` where the manual lists a 32-bit form (D + mnemonic: DMOV) and `p`
where it lists a pulse form (mnemonic + P: MOVP; DMOVP when both). Instructions spelt
with symbols or a dot (LD=, B+, $MOV, ZP.OPEN, G.OUTPUT ...) cannot be label names and are
left out; the ST spellings of the dotted ones (ZP_OPEN, G_OUTPUT) are
verifier.st.library's. Read by verifier.st.melsec.
"""

NAMES = """
# sequence instructions: contact, association, output, shift, master control, termination
LD
LDI
AND
ANI
OR
ORI
LDP
LDF
ANDP
ANDF
ORP
ORF
LDPI
LDFI
ANDPI
ANDFI
ORPI
ORFI
ANB
ORB
MPS
MRD
MPP
INV
MEP
MEF
EGP
EGF
OUT
SET
RST
PLS
PLF
FF
DELTA p
SFT p
MC
MCR
FEND
END
STOP
NOP
NOPLF
PAGE
# basic instructions: arithmetic, BCD/BIN conversion, transfer, program branch
ADD dp
SUB dp
MUL dp
DIV dp
INC dp
DEC dp
BCD dp
BIN dp
FLT dp
INT dp
DBL p
WORD p
GRY dp
GBIN dp
NEG dp
ENEG p
EDNEG p
BKBCD p
BKBIN p
ECON p
EDCON p
MOV dp
EMOV p
EDMOV p
CML dp
BMOV p
FMOV dp
XCH dp
BXCH p
SWAP p
CJ
SCJ
JMP
GOEND
DI
EI
IMASK
IRET
RFS p
UDCNT1
UDCNT2
TTMR
STMR
ROTC
RAMP
SPD
PLSY
PWM
MTR
# application instructions: logical operation, rotation, shift, bit processing
WAND p
DAND p
BKAND p
WOR p
DOR p
BKOR p
WXOR p
DXOR p
BKXOR p
WXNR p
DXNR p
BKXNR p
ROR dp
RCR dp
ROL dp
RCL dp
SFR p
SFL p
BSFR p
BSFL p
DSFR p
DSFL p
BSET p
BRST p
TEST dp
BKRST p
# application instructions: data processing, structure creation, table operation
SER dp
SUM dp
DECO p
ENCO p
SEG p
DIS p
UNI p
NDIS p
NUNI p
WTOB p
BTOW p
MAX dp
MIN dp
SORT d
WSUM dp
MEAN dp
FOR
NEXT
BREAK p
CALL p
RET
FCALL p
ECALL p
EFCALL p
XCALL
FIFW p
FIFR p
FPOP p
FINS p
FDEL p
# application instructions: buffer memory access, display, debugging, character string
FROM dp
TO dp
PR
PRC
LEDR
CHKST
CHK
CHKCIR
CHKEND
BINDA dp
BINHA dp
BCDDA dp
DABIN dp
HABIN dp
DABCD dp
COMRD p
LEN p
STR dp
VAL dp
ESTR p
EVAL p
ASC p
HEX p
RIGHT p
LEFT p
MIDR p
MIDW p
INSTR p
EMOD p
EREXP p
STRINS p
STRDEL p
# application instructions: special functions (real number, BCD, random)
SIN p
COS p
TAN p
ASIN p
ACOS p
ATAN p
SIND p
COSD p
TAND p
ASIND p
ACOSD p
ATAND p
RAD p
DEG p
RADD p
DEGD p
POW p
POWD p
SQR p
SQRD p
EXP p
EXPD p
LOG p
LOGD p
LOG10 p
LOG10D p
BSQR dp
BSIN dp
BCOS dp
BTAN dp
BASIN dp
BACOS dp
BATAN dp
RND p
SRND p
# application instructions: data control, switching, clock, peripheral, program control
LIMIT dp
BAND dp
ZONE dp
SCL dp
SCL2 dp
RSET p
QDRSET p
QCDSET p
DATERD p
DATEWR p
SECOND dp
HOUR dp
MSG
PKEY
PSTOP p
POFF p
PSCAN p
COM
CCOM
ZPUSH p
ZPOP p
ADRSET p
KEY
DUTY
ZRRDB p
ZRWRB p
TRACE
TRACER
UNIRD p
TYPERD p
RBMOV p
TIMCHK
IXSET
IXDEV
IX
IXEND
# application instructions: PID control, zone reset
PIDINIT p
PIDCONT p
PIDSTOP p
PIDRUN p
PIDPRMW p
ZRST p
"""
