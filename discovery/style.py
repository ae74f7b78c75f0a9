"""report.html's stylesheet, inlined in the page so it opens offline: system fonts only (nothing fetched), a clear
hierarchy (title block, the verdict in a ruled box opening with its headline, numbered sections), booktabs-like
tables with right-aligned tabular numbers, one column at a phone's width, and a print layout (A4, no page break
inside a table row or the verdict, the raw data left out)."""

STYLE = """
:root{--ink:#1c2228;--muted:#5a6571;--rule:#cfd6dd;--soft:#f4f6f8;--accent:#1f5f99;--chosen:#eef5ec;--flag:#8a4b00}
*{box-sizing:border-box}
html{font-size:16px;-webkit-text-size-adjust:100%}
body{margin:0;color:var(--ink);background:#fff;
 font:1rem/1.55 system-ui,-apple-system,"Segoe UI",Roboto,"Helvetica Neue","Liberation Sans","DejaVu Sans",Arial,sans-serif}
header.title,main,footer{max-width:76rem;margin:0 auto;padding:0 1.5rem}
header.title{padding-top:1.6rem;padding-bottom:.8rem;border-bottom:3px solid var(--accent)}
header.title .kicker{margin:0;color:var(--muted);font-size:.8rem;letter-spacing:.08em;text-transform:uppercase}
h1{font-size:1.75rem;line-height:1.25;margin:.2rem 0 .6rem;font-weight:650}
h2{font-size:1.3rem;margin:2.4rem 0 .6rem;padding-bottom:.25rem;border-bottom:1px solid var(--rule);font-weight:650}
h3{font-size:1.05rem;margin:1.4rem 0 .4rem;font-weight:650}
p,li,dd{max-width:62rem}
dl.meta{display:flex;flex-wrap:wrap;gap:.2rem 1.6rem;margin:0;font-size:.9rem;color:var(--muted)}
dl.meta div{display:flex;gap:.35rem}dl.meta dt{font-weight:600}dl.meta dd{margin:0}
section.verdict{margin:1.6rem 0 0;padding:1.1rem 1.4rem 1.2rem;background:var(--soft);border:1px solid var(--rule);
 border-left:6px solid var(--accent);break-inside:avoid}
section.verdict h2{margin:0 0 .4rem;border:0;padding:0;font-size:.85rem;color:var(--muted);letter-spacing:.08em;
 text-transform:uppercase}
section.verdict .headline{margin:0 0 1rem;overflow-wrap:break-word}
section.verdict .headline p{font-size:1.25rem;line-height:1.4;font-weight:600;margin:0 0 .35rem}
section.verdict .headline p:first-child{font-weight:700}
section.verdict .headline p:nth-child(3){font-size:1.05rem;font-weight:400}
section.verdict dl{display:grid;grid-template-columns:11rem 1fr;gap:.55rem 1.2rem;margin:0}
section.verdict dt{font-weight:650;color:var(--accent)}
section.verdict dd{margin:0}section.verdict ul{margin:0;padding-left:1.1rem}section.verdict li+li{margin-top:.25rem}
section.verdict .paragraph{margin:1rem 0 0;font-size:.92rem;color:var(--muted)}
.missing{background:#fff6e8;padding:.6rem .8rem;border-left:4px solid var(--flag)}
.note{color:var(--muted);font-size:.9rem}
table{border-collapse:collapse;margin:.6rem 0 1rem;font-size:.88rem;border-top:2px solid var(--ink);
 border-bottom:2px solid var(--ink)}
caption{caption-side:top;text-align:left;font-weight:600;padding:0 0 .35rem;font-size:.9rem}
th,td{padding:.3rem .7rem;vertical-align:top;text-align:left}
thead th{border-bottom:1px solid var(--ink);font-weight:600;vertical-align:bottom}
th .unit{display:block;font-weight:400;color:var(--muted);font-size:.8rem}
tbody tr+tr td{border-top:1px solid var(--rule)}
td.num,th.num{text-align:right;font-variant-numeric:tabular-nums}td.num{white-space:nowrap}td.wide{min-width:20rem}
tr.chosen td{background:var(--chosen)}td.flag{color:var(--flag);font-weight:600}
.table-wrap{overflow-x:auto}
.plots{display:flex;flex-wrap:wrap;gap:.8rem;margin:.6rem 0}
.plots>div{border:1px solid var(--rule)}
details.raw{margin:2.4rem 0 1rem;border-top:1px solid var(--rule);padding-top:.6rem}
details.raw summary{cursor:pointer;color:var(--muted)}
details.raw pre{font-size:.78rem;background:var(--soft);padding:.8rem;overflow-x:auto;max-height:40rem}
footer{padding-top:.6rem;padding-bottom:2rem;color:var(--muted);font-size:.8rem}
@media (max-width:40rem){
 header.title,main,footer{padding-left:.9rem;padding-right:.9rem}
 section.verdict{padding:.9rem 1rem 1rem;border-left-width:4px}
 section.verdict .headline p{font-size:1.1rem}
 section.verdict dl{grid-template-columns:1fr;gap:.2rem}
 section.verdict dd+dt{margin-top:.6rem}
}
@media print{
 @page{size:A4;margin:16mm 14mm}
 html{font-size:10pt}
 header.title,main,footer{max-width:none;padding:0}
 section.verdict{background:none}
 h2{break-after:avoid}
 tr,.plots>div{break-inside:avoid}
 details.raw{display:none}
}
"""
"""The stylesheet of report.html."""
