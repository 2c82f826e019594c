import nbformat, os
from nbclient import NotebookClient
os.environ['NBGRADER_EXECUTION']='validate'
nb=nbformat.read('alice/ex06/ex06_ros_bags.ipynb',4)
NotebookClient(nb, timeout=120, allow_errors=True, kernel_name='python3').execute()
for c in nb.cells[:8]:
    if c.cell_type=='code':
        for o in c.outputs:
            print(c.metadata.get('nbgrader',{}).get('grade_id'), o.get('output_type'), (o.get('text') or o.get('evalue') or '')[:400])
