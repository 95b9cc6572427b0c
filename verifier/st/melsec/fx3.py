"""The instruction names of the FX3 CPUs (FX3S/FX3G/FX3GC/FX3U/FX3UC), which GX Works2
refuses as label names in an FXCPU project (docs/st-dialect.md section 4).

Source: FX3S/FX3G/FX3GC/FX3U/FX3UC Series Programming Manual - Basic & Applied Instruction
Edition (JY997D16601), chapter 3 "Instruction List" (basic instructions, step ladder
instructions, applied instructions FNC 00 to FNC 295 by FNC number). One line an
instruction: its mnemonic, then `d` where the manual lists a 32-bit form (D + mnemonic:
DMOV) and `p` where it lists a pulse form (mnemonic + P: MOVP; DMOVP when both); a
mnemonic the manual lists only as a 32-bit instruction (ECMP: DECMP, DECMPP) is kept with
its own name too. Instructions spelt with symbols (LD=, BK+, $MOV ...) cannot be label
names and are left out. Read by verifier.st.melsec.
"""

NAMES = """
# basic instructions (chapter 7) and step ladder (chapter 35)
LD
LDI
LDP
LDF
AND
ANI
ANDP
ANDF
OR
ORI
ORP
ORF
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
MC
MCR
NOP
END
STL
RET
# FNC 00-09 program flow
CJ p
CALL p
SRET
IRET
EI
DI
FEND
WDT p
FOR
NEXT
# FNC 10-19 move and compare
CMP dp
ZCP dp
MOV dp
SMOV p
CML dp
BMOV p
FMOV dp
XCH dp
BCD dp
BIN dp
# FNC 20-29 arithmetic and logical operation
ADD dp
SUB dp
MUL dp
DIV dp
INC dp
DEC dp
WAND dp
WOR dp
WXOR dp
NEG dp
# FNC 30-39 rotation and shift
ROR dp
ROL dp
RCR dp
RCL dp
SFTR p
SFTL p
WSFR p
WSFL p
SFWR p
SFRD p
# FNC 40-49 data operation
ZRST p
DECO p
ENCO p
SUM dp
BON dp
MEAN dp
ANS
ANR p
SQR dp
FLT dp
# FNC 50-59 high speed processing
REF p
REFF p
MTR
HSCS d
HSCR d
HSZ d
SPD d
PLSY d
PWM
PLSR d
# FNC 60-69 handy instructions
IST
SER dp
ABSD d
INCD
TTMR
STMR
ALT p
RAMP
ROTC
SORT
# FNC 70-79 external FX I/O devices
TKY d
HKY d
DSW
SEGD p
SEGL
ARWS
ASC
PR
FROM dp
TO dp
# FNC 80-89 external FX devices
RS
PRUN dp
ASCI p
HEX p
CCD p
VRRD p
VRSC p
RS2
PID
# FNC 100-109 data transfer 2
ZPUSH p
ZPOP p
# FNC 110-139 floating point (32-bit only: DECMP, DECMPP ...)
ECMP dp
EZCP dp
EMOV dp
ESTR dp
EVAL dp
EBCD dp
EBIN dp
EADD dp
ESUB dp
EMUL dp
EDIV dp
EXP dp
LOGE dp
LOG10 dp
ESQR dp
ENEG dp
INT dp
SIN dp
COS dp
TAN dp
ASIN dp
ACOS dp
ATAN dp
RAD dp
DEG dp
# FNC 140-149 data operation 2
WSUM dp
WTOB p
BTOW p
UNI p
DIS p
SWAP dp
SORT2 d
# FNC 150-159 positioning control
DSZR
DVIT d
TBL d
ABS d
ZRN d
PLSV d
DRVI d
DRVA d
# FNC 160-169 real time clock control
TCMP p
TZCP p
TADD p
TSUB p
HTOS dp
STOH dp
TRD p
TWR p
HOUR d
# FNC 170-179 external device
GRY dp
GBIN dp
RD3A
WR3A
# FNC 180-189 alternate instruction and others
EXTR
COMRD p
RND p
DUTY
CRC p
HCMOV d
# FNC 200-209 character string control
STR dp
VAL dp
LEN p
RIGHT p
LEFT p
MIDR p
MIDW p
INSTR p
# FNC 210-219 data operation 3
FDEL p
FINS p
POP p
SFR p
SFL p
# FNC 256-269 data table operation
LIMIT dp
BAND dp
ZONE dp
SCL dp
DABIN dp
BINDA dp
SCL2 dp
# FNC 270-276 external device communication (inverter, MODBUS)
IVCK
IVDR
IVRD
IVWR
IVBWR
IVMC
ADPRW
# FNC 278-280 extension file register control and high speed counter
RBFM
WBFM
HSCT d
# FNC 290-295 extension file register control
LOADR p
SAVER
INITR p
LOGR p
RWER p
INITER p
"""
