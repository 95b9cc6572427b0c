"""The instruction names of the FX5 CPUs (FX5U/FX5UC/FX5UJ/FX5S), which GX Works3 refuses
as label names (docs/st-dialect.md section 4: every instruction name is a reserved word).

Source: MELSEC iQ-F FX5 Programming Manual (Instructions, Standard Functions/Function
Blocks) (SH-122614ENG), Part 2 "CPU module instructions": sequence instructions, basic
instructions, application instructions, step ladder, the built-in function and module
instructions, in the manual's instruction index. One line an instruction: its mnemonic,
then `d` where the manual lists a 32-bit form (D + mnemonic: DMOV) and `p` where it lists
a pulse form (mnemonic + P: MOVP; DMOVP when both). Instructions spelt with symbols or a
dot (LD=, B+, $MOV, SP.SOCOPEN ...) cannot be label names and are left out; the ST
spellings of the dotted ones (SP_SOCOPEN) are verifier.st.library's. Read by
verifier.st.melsec.
"""

NAMES = """
# sequence instructions: contact, association, output, shift, master control, end
LD
LDI
LDP
LDF
LDPI
LDFI
AND
ANI
ANDP
ANDF
ANDPI
ANDFI
OR
ORI
ORP
ORF
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
OUT
SET
RST
PLS
PLF
FF
ALT p
ALTD p
SFT p
MC
MCR
FEND
END
NOP
STL
RETSTL
# basic instructions: arithmetic, logical, bit processing, conversion, transfer
ADD dp
SUB dp
MUL dp
DIV dp
INC dp
DEC dp
WAND p
DAND p
WOR p
DOR p
WXOR p
DXOR p
WXNR p
DXNR p
BKAND p
BKOR p
BKXOR p
BKXNR p
BSET p
BRST p
TEST dp
BKRST p
BCD dp
BIN dp
GRY dp
GBIN dp
NEG dp
BKBCD p
BKBIN p
FLT dp
INT2FLT p
INT2DBL p
UINT2FLT p
UINT2DBL p
DINT2FLT p
DINT2DBL p
UDINT2FLT p
UDINT2DBL p
FLT2INT p
FLT2UINT p
FLT2DINT p
FLT2UDINT p
DBL2INT p
DBL2UINT p
DBL2DINT p
DBL2UDINT p
INT2UINT p
INT2DINT p
INT2UDINT p
UINT2INT p
UINT2DINT p
UINT2UDINT p
DINT2INT p
DINT2UINT p
DINT2UDINT p
UDINT2INT p
UDINT2UINT p
UDINT2DINT p
DBL2FLT p
FLT2DBL p
PRUN dp
MOV dp
CML dp
CMLB p
BMOV p
FMOV dp
XCH dp
BXCH p
SWAP dp
SMOV p
# basic instructions: program branch, program execution control, structure creation
CJ p
GOEND
DI
EI
IMASK
SIMASK
IRET
WDT p
FOR
NEXT
BREAK p
CALL p
RET
SRET
XCALL
# application instructions: rotation, shift, data processing
ROR dp
ROL dp
RCR dp
RCL dp
SFTR p
SFTL p
WSFR p
WSFL p
SFR p
SFL p
BSFR p
BSFL p
SFWR p
SFRD p
DSFR p
DSFL p
SER dp
SUM dp
BON dp
DECO p
ENCO p
SEGD p
DIS p
UNI p
NDIS p
NUNI p
WTOB p
BTOW p
MAX dp
MIN dp
SORTTBL
SORTTBL2 d
SORT2 d
WSUM dp
MEAN dp
SQR dp
ABS dp
ZRST p
ZPUSH p
ZPOP p
# application instructions: structure, data table, string, real number, random
FDEL p
FINS p
POP p
FIFW p
FIFR p
FPOP p
LEN p
STR dp
VAL dp
ESTR p
EVAL p
ASCI p
HEX p
RIGHT p
LEFT p
MIDR p
MIDW p
INSTR p
STRINS p
STRDEL p
DABIN dp
BINDA dp
EMOD p
EREXP p
ECMP p
EZCP p
EMOV p
EDMOV p
EADD p
ESUB p
EMUL p
EDIV p
EBCD p
EBIN p
ENEG p
EDNEG p
ESQR p
EDSQR p
EXP p
EDEXP p
LOGE p
EDLOGE p
LOG10 p
EDLOG10 p
SIN p
COS p
TAN p
ASIN p
ACOS p
ATAN p
RAD p
DEG p
EDSIN p
EDCOS p
EDTAN p
EDASIN p
EDACOS p
EDATAN p
EDRAD p
EDDEG p
EMAX p
EMIN p
EDMAX p
EDMIN p
INT p
RND p
SRND p
# application instructions: data control, clock, timer, counter, handy
LIMIT dp
BAND dp
ZONE dp
SCL dp
SCL2 dp
DATERD p
DATEWR p
TCMP p
TZCP p
TADD p
TSUB p
HTOS dp
STOH dp
TRD p
TWR p
HOUR d
TTMR
STMR
ROTC
RAMP
SPD d
IST
ABSD d
INCD
HKY d
TKY d
DSW
SEGL
ARWS
ASC
PR
# application instructions: communication, module access, file register, logging
RS2
ADPRW
IVCK
IVDR
IVRD
IVWR
IVBWR
IVMC
FROM dp
TO dp
RBFM
WBFM
PID
CRC p
CCD p
COMRD p
LOADR p
SAVER
INITR p
LOGR p
RWER p
INITER p
EROMWR p
DUTY
UDCNTF
# built-in positioning and high-speed I/O
DSZR d
DVIT d
TBL
DRVTBL
DRVMUL
ZRN d
PLSV d
DRVI d
DRVA d
PLSY d
PWM d
PLSR d
HIOEN d
HCMOV d
DHSCS
DHSCR
DHSZ
DHSCT
"""
